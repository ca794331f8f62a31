"""The Python module raystream (python/), run by CTest (python_test: PYTHONPATH=BUILD/python)
and against the installed wheel (tests/python_wheel_test.sh).

- a render of builtin:cornell equals the command's EXR bit for bit, and numpy.asarray takes the
  pixels without a copy;
- a scene built from numpy arrays (normals and UVs that are not axis-aligned) equals the same
  scene from a dict and from a JSON file;
- a render cancelled by its progress callback returns at once with fewer samples; Ctrl-C
  (SIGINT) raises KeyboardInterrupt out of a long render; the GIL is free while it renders;
- hostile calls raise ValueError / OSError with the message and never crash.
"""
import json
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import raystream

RS_BINARY = os.environ.get("RS_BINARY")


def bits(a):
    return np.ascontiguousarray(a, dtype=np.float32).view(np.uint32)


@pytest.mark.skipif(not RS_BINARY, reason="RS_BINARY (the raystream command) is not set")
def test_render_equals_cli_exr(tmp_path):
    img = raystream.render("builtin:cornell", spp=16)
    a = np.asarray(img)
    assert a.shape == (600, 600, 3) and a.dtype == np.float32
    assert not a.flags.owndata  # a view of the image's memory, not a copy

    out = tmp_path / "cli.exr"
    subprocess.run([RS_BINARY, "render", "builtin:cornell", "--spp", "16", "-q", "-o", str(out)],
                   check=True)
    b = np.asarray(raystream.read_image(out))
    assert np.array_equal(bits(a), bits(b))
    assert a.mean() > 0.01


def test_pixels_are_the_images_memory():
    img = raystream.render("builtin:cornell", width=32, spp=1, aov=["depth"])
    a = np.asarray(img)
    a[0, 0, 0] = 1234.5  # numpy's array is the image's memory: the write shows everywhere
    assert np.asarray(img)[0, 0, 0] == 1234.5 and img.view[0, 0, 0] == 1234.5
    if sys.version_info >= (3, 11):  # the buffer protocol on the image itself
        mv = memoryview(img)
        assert mv.format == "f" and mv.shape == (32, 32, 3) and not mv.readonly
        assert mv[0, 0, 0] == 1234.5
        depth = memoryview(img.layers["depth"])
        assert depth.shape == (32, 32) and depth.format == "f"
    assert np.asarray(img.layers["depth"]).shape == (32, 32)


@pytest.mark.skipif(not RS_BINARY, reason="RS_BINARY (the raystream command) is not set")
def test_options_equal_cli(tmp_path):
    opts = dict(width=90, height=70, spp=3, seed=11, max_depth=5, sampler="independent",
                filter="box:0.5", devices="cpu:1,gpu")
    img = raystream.render("builtin:materials", **opts)
    out = tmp_path / "cli.pfm"
    args = [RS_BINARY, "render", "builtin:materials", "-q", "-o", str(out)]
    for k, v in opts.items():
        args += ["--" + k.replace("_", "-"), str(v)]
    subprocess.run(args, check=True)
    assert np.array_equal(bits(np.asarray(img)), bits(np.asarray(raystream.read_image(out))))


SCENE = {
    "camera": {"from": [0.3, 1.2, 3.5], "at": [0, 0.4, 0], "up": [0.1, 1, 0], "vfov": 35},
    "image": {"width": 72, "height": 54},
    "background": [0.05, 0.07, 0.1],
    "materials": {"red": {"type": "lambertian", "albedo": [0.7, 0.2, 0.15]},
                  "lamp": {"type": "light", "emission": [6, 5, 4]}},
    "objects": [],
}
V = np.array([[-2, 0, -2], [2, 0.2, 2], [2, 0, -2], [-2, 0.1, 2]], dtype=np.float32)
N = np.array([[0, 1, 0], [0.28734789, 0.95782629, 0], [0, 1, 0], [0, 0.99503719, 0.09950372]],
             dtype=np.float32)
UV = np.array([[0, 0], [1, 1], [1, 0], [0, 1]], dtype=np.float32)
F = np.array([[0, 1, 2], [0, 3, 1]], dtype=np.int64)


def json_scene():
    s = json.loads(json.dumps(SCENE))
    for tri in F:
        s["objects"].append({"type": "triangle", "vertices": V[tri].tolist(),
                             "normals": N[tri].ravel().tolist(), "uv": UV[tri].ravel().tolist(),
                             "material": "red"})
    s["objects"].append({"type": "quad", "q": [-0.5, 2, -0.5], "u": [1, 0, 0], "v": [0, 0, 1],
                         "material": "lamp"})
    return s


def test_numpy_scene_equals_json(tmp_path):
    scene = raystream.Scene()
    red = scene.add_material(type="lambertian", albedo=(0.7, 0.2, 0.15))
    lamp = scene.add_material({"type": "light", "emission": [6, 5, 4]})
    scene.add_mesh(V, F, normals=N, uvs=UV, material=red)
    scene.add_quad((-0.5, 2, -0.5), (1, 0, 0), (0, 0, 1), material=lamp)
    scene.set_camera((0.3, 1.2, 3.5), (0, 0.4, 0), up=(0.1, 1, 0), vfov=35)
    scene.set_background((0.05, 0.07, 0.1))
    scene.set_image_size(72, 54)
    assert scene.counts == (0, 1, 2, 2)
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(json_scene()))
    a = np.asarray(raystream.render(scene, spp=8))
    b = np.asarray(raystream.render(raystream.load_json(json_scene()), spp=8))
    c = np.asarray(raystream.render(raystream.load(path), spp=8))
    d = np.asarray(raystream.render(str(path), spp=8))
    assert a.shape == (54, 72, 3) and a.mean() > 0.01
    for other in (b, c, d):
        assert np.array_equal(bits(a), bits(other))
    # float64 vertices and int32 indices are converted: the same scene
    s2 = raystream.Scene()
    s2.add_material(type="lambertian", albedo=(0.7, 0.2, 0.15))
    s2.add_mesh(V.astype(np.float64), F.astype(np.int32), normals=N, uvs=UV)
    assert s2.counts == (0, 0, 2, 1)


def test_instances_and_lights_equal_json():
    tet = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float32)
    tet_faces = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])
    m1 = [[0.8, -0.3, 0.1, -1], [0.3, 0.9, 0, 0.2], [-0.1, 0.05, 1.2, 0.3], [0, 0, 0, 1]]
    m2 = [[0.5, 0, 0.6, 1.1], [0, 1.4, 0, 0], [-0.6, 0, 0.5, -0.4]]
    light = {"type": "point_light", "position": [0.5, 3, 1], "intensity": [9, 8, 7]}
    s = raystream.Scene()
    s.add_material(type="lambertian", albedo=(0.6, 0.6, 0.6))
    green = s.add_material(type="lambertian", albedo=(0.2, 0.7, 0.3))
    s.add_mesh([[-3, 0, -3], [3, 0, 3], [3, 0, -3], [-3, 0, 3]], [[0, 1, 2], [0, 3, 1]])
    proto = s.add_prototype(tet, tet_faces, material=green)
    s.add_instance(proto, m1)
    s.add_instance(proto, np.array(m2))
    s.add_light(light)
    s.set_camera((0.5, 2.5, 5), (0, 0.5, 0))
    s.set_image_size(64, 48)
    assert s.counts == (0, 0, 10, 2)
    d = {"camera": {"from": [0.5, 2.5, 5], "at": [0, 0.5, 0]},
         "image": {"width": 64, "height": 48},
         "materials": {"grey": {"type": "lambertian", "albedo": [0.6, 0.6, 0.6]},
                       "green": {"type": "lambertian", "albedo": [0.2, 0.7, 0.3]}},
         "groups": {"tet": [{"type": "triangle", "vertices": tet[f].tolist(), "material": "green"}
                            for f in tet_faces]},
         "objects": [{"type": "triangle", "vertices": [[-3, 0, -3], [3, 0, 3], [3, 0, -3]],
                      "material": "grey"},
                     {"type": "triangle", "vertices": [[-3, 0, -3], [-3, 0, 3], [3, 0, 3]],
                      "material": "grey"},
                     {"type": "instance", "group": "tet",
                      "transform": [{"matrix": sum(m1, [])}]},
                     {"type": "instance", "group": "tet",
                      "transform": [{"matrix": sum(m2, []) + [0, 0, 0, 1]}]},
                     light]}
    a = np.asarray(raystream.render(s, spp=8))
    b = np.asarray(raystream.render(raystream.load_json(d), spp=8))
    assert a.mean() > 0.01 and np.array_equal(bits(a), bits(b))
    with pytest.raises(ValueError, match="prototype 5"):
        s.add_instance(5, m2)
    with pytest.raises(ValueError, match="affine"):
        s.add_instance(proto, [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [1, 0, 0, 1]])
    with pytest.raises(ValueError, match="point_light"):
        s.add_light(type="sphere")


def test_aov_layers_and_write(tmp_path):
    img = raystream.render("builtin:cornell", width=40, spp=2, aov=["albedo", "normal", "depth"])
    assert set(img.layers) == {"albedo", "normal", "depth"}
    assert np.asarray(img.layers["albedo"]).shape == (40, 40, 3)
    assert np.asarray(img.layers["depth"]).shape == (40, 40)
    assert np.asarray(img.layers["depth"]).max() > 0
    out = tmp_path / "x.exr"
    img.write(out)
    assert np.array_equal(bits(np.asarray(img)), bits(np.asarray(raystream.read_image(out))))
    mv = img.view
    assert mv.format == "f" and mv.shape == (40, 40, 3)


def test_cancel_by_progress():
    seen = []

    def progress(fraction):
        seen.append(fraction)
        return False

    img = raystream.render("builtin:cornell", width=120, spp=4096, threads=1, progress=progress)
    assert img.cancelled and img.spp < 4096
    assert len(seen) == 1 and 0.0 <= seen[0] <= 1.0


def test_progress_exception_propagates():
    def progress(fraction):
        raise ZeroDivisionError("from the callback")

    with pytest.raises(ZeroDivisionError):
        raystream.render("builtin:cornell", width=64, spp=4096, threads=1, progress=progress)


def test_ctrl_c_raises_keyboard_interrupt():
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    t0 = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        raystream.render("builtin:cornell", spp=100000, threads=1)
    timer.join()
    assert time.monotonic() - t0 < 60  # 100000 spp would take hours


def test_gil_released_while_rendering():
    ticks = []
    done = threading.Event()

    def work():
        raystream.render("builtin:cornell", width=200, spp=64, threads=1)
        done.set()

    t = threading.Thread(target=work)
    t.start()
    while not done.is_set():
        ticks.append(1)
        time.sleep(0.001)
    t.join()
    assert len(ticks) > 20


@pytest.mark.parametrize("call, exc, text", [
    (lambda: raystream.render("builtin:nope"), ValueError, "nope"),
    (lambda: raystream.render("/no/such/scene.json"), OSError, "no such scene file"),
    (lambda: raystream.render("builtin:cornell", spp=-1), ValueError, "--spp"),
    (lambda: raystream.render("builtin:cornell", width=10 ** 9), ValueError, "--width"),
    (lambda: raystream.render("builtin:cornell", bogus=3), ValueError, "bogus"),
    (lambda: raystream.render("builtin:cornell", output="x.png"), ValueError, "--output"),
    (lambda: raystream.render("builtin:cornell", spp=object()), ValueError, "spp"),
    (lambda: raystream.render(42), ValueError, "scene"),
    (lambda: raystream.render("builtin:cornell", progress=3), ValueError, "callable"),
    (lambda: raystream.load("/no/such.gltf"), OSError, "no such"),
    (lambda: raystream.load_json("{not json"), ValueError, "syntax"),
    (lambda: raystream.read_image("/no/such.exr"), OSError, "/no/such.exr"),
])
def test_hostile_calls(call, exc, text):
    with pytest.raises(exc) as e:
        call()
    assert text in str(e.value)


@pytest.mark.parametrize("vertices, indices, text", [
    (V.astype(np.complex64), F, "complex"),
    (np.array([["a", "b", "c"]]), F[:0], "expected numbers"),
    (V[:, :2], F, "N x 3"),
    (V, F[:, :2], "N x 3"),
    (V, F.astype(np.float32), "whole numbers"),
    (V, F + 10, "[0, 4)"),
    (V, -F - 1, "[0, 4)"),
    (np.where(np.arange(12).reshape(4, 3) == 7, np.nan, V), F, "not finite"),
])
def test_hostile_meshes(vertices, indices, text):
    s = raystream.Scene()
    s.add_material(type="lambertian")
    with pytest.raises(ValueError) as e:
        s.add_mesh(vertices, indices)
    assert text in str(e.value)
    assert s.counts == (0, 0, 0, 1)


def test_hostile_scene_calls():
    s = raystream.Scene()
    with pytest.raises(ValueError, match="material 0"):
        s.add_mesh(V, F)
    with pytest.raises(ValueError, match="glitter"):
        s.add_material(type="glitter")
    with pytest.raises(ValueError, match="three numbers"):
        s.add_sphere((0, 0), 1.0)
    with pytest.raises(ValueError, match="image size"):
        s.set_image_size(10 ** 6, 10)
    with pytest.raises(ValueError, match="normals"):
        s.add_material(type="lambertian")
        s.add_mesh(V, F, normals=N[:2])
    with pytest.raises(ValueError, match="background"):
        raystream.render(s, background="sky")


def test_version():
    assert raystream.__version__.count(".") == 2
    assert raystream.version.startswith(raystream.__version__)
