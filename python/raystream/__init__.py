"""raystream: a heterogeneous CPU+GPU streaming path tracer, from Python.

    import numpy, raystream
    img = raystream.render("builtin:cornell", spp=16)      # anything `raystream render` takes
    a = numpy.asarray(img)                                 # (600, 600, 3) float32, no copy
    img.write("cornell.exr")

render()'s keywords are the command's options with "_" for "-" (spp, width, height, seed,
max_depth, sampler, filter, devices, aov, denoise, tev, ...; `raystream render --help`), and
give the same image as the command, bit for bit.  Scenes come from files (load), from a JSON
description (load_json, a dict or its text: docs/scene-format.md), or are built here (Scene:
materials, meshes from numpy arrays, spheres, quads, camera, background).  The GIL is released
while rendering; Ctrl-C stops the render (KeyboardInterrupt).  Errors are ValueError (bad
arguments), OSError (files), MemoryError and RuntimeError, with raystream's one-line message.
"""
import json as _json
from array import array as _array

from . import _raystream as _c

__all__ = ["Image", "Scene", "load", "load_json", "read_image", "render", "version",
           "__version__"]

version_number, version = _c.version()
__version__ = "%d.%d.%d" % (version_number // 10000, version_number // 100 % 100,
                            version_number % 100)


class _Planes(_c.Pixels):
    """Floats of a width x height image, channels per pixel.  The buffer protocol (Python 3.11
    and later: memoryview(img), numpy.asarray(img) take the image's own memory, format "f",
    shape (height, width[, channels])); on 3.9 and 3.10 numpy takes it through the array
    interface, also without a copy.  `.view` is a memoryview of it on every version."""

    def __init__(self, data, width, height, channels):
        super().__init__(data, height, width, channels)
        self._data = data  # a bytearray
        self.width, self.height, self.channels = width, height, channels
        self.shape = (height, width, channels) if channels > 1 else (height, width)
        if _c.PIXELS_HAVE_BUFFER:
            self.view = memoryview(self)
        else:
            self.view = memoryview(data).cast("B").cast("f", self.shape)

    if not _c.PIXELS_HAVE_BUFFER:
        @property
        def __array_interface__(self):
            return {"version": 3, "shape": self.shape, "typestr": "<f4",
                    "data": self.view, "strides": None}

    def __len__(self):
        return self.height

    def __getitem__(self, index):
        return self.view[index]

    def tolist(self):
        return self.view.tolist()


class Image(_Planes):
    """A rendered image: numpy.asarray(image) is its height x width x 3 float32 pixels (linear
    RGB, top row first).  `layers` holds the AOV passes asked for with aov= ("albedo", "normal":
    3 channels; "depth", "samples": 1) and "noisy" with denoise=True."""

    def __init__(self, parts):
        cap, width, height, spp, cancelled, pixels, layers = parts
        super().__init__(pixels, width, height, 3)
        self._cap = cap
        self.spp = spp
        self.cancelled = bool(cancelled)
        self.layers = {name: _Planes(data, width, height, ch)
                       for name, (ch, data) in layers.items()}

    def write(self, path):
        """Writes the image as `raystream render -o PATH` would (.exr with its layers, .pfm,
        .hdr linear; .png and other 8-bit files through the render's view)."""
        _c.image_write(self._cap, _path(path))

    def __repr__(self):
        return "<raystream.Image %dx%d, %g spp%s%s>" % (
            self.width, self.height, self.spp,
            ", layers " + ",".join(self.layers) if self.layers else "",
            ", cancelled" if self.cancelled else "")


def _path(p):
    import os
    p = os.fspath(p)
    if not isinstance(p, str):
        p = p.decode()
    return p


def _floats(x, name, width):
    """Rows of `width` numbers as packed float32 bytes, and how many rows."""
    try:
        import numpy as np
    except ImportError:
        np = None
    if np is not None:
        a = np.asarray(x)
        if a.dtype.kind not in "fiu" or a.dtype.kind == "b":
            raise ValueError("%s: expected numbers, not %s" % (name, a.dtype))
        if a.ndim != 2 or a.shape[1] != width:
            raise ValueError("%s: expected an N x %d array, not one of shape %s"
                             % (name, width, a.shape))
        return np.ascontiguousarray(a, dtype="<f4").tobytes(), a.shape[0]
    rows = list(x)
    flat = []
    for r in rows:
        r = list(r)
        if len(r) != width:
            raise ValueError("%s: expected rows of %d numbers" % (name, width))
        flat.extend(float(v) for v in r)
    return _array("f", flat).tobytes(), len(rows)


def _indices(x, n_vertices):
    try:
        import numpy as np
    except ImportError:
        np = None
    if np is not None:
        a = np.asarray(x)
        if a.dtype.kind not in "iu":
            raise ValueError("indices: expected whole numbers, not %s" % a.dtype)
        if a.ndim != 2 or a.shape[1] != 3:
            raise ValueError("indices: expected an N x 3 array, not one of shape %s" % (a.shape,))
        if a.size and (a.min() < 0 or a.max() >= n_vertices):
            raise ValueError("indices: each must be in [0, %d)" % n_vertices)
        return np.ascontiguousarray(a, dtype="<u4").tobytes()
    flat = []
    for r in x:
        r = [int(v) for v in r]
        if len(r) != 3:
            raise ValueError("indices: expected rows of 3 numbers")
        if min(r) < 0 or max(r) >= n_vertices:
            raise ValueError("indices: each must be in [0, %d)" % n_vertices)
        flat.extend(r)
    return _array("I", flat).tobytes()


def _json_text(what, value, fields):
    """A scene file's object given as a dict, its JSON text, or keywords: its JSON text."""
    if value is None:
        value = fields
    elif fields:
        raise ValueError("%s: give a dict or keywords, not both" % what)
    return value if isinstance(value, str) else _json.dumps(value)


class Scene:
    """A scene: raystream.load(...), raystream.load_json(...), or Scene() built here."""

    def __init__(self, _cap=None):
        self._cap = _cap if _cap is not None else _c.scene_create()

    def add_material(self, material=None, **fields):
        """A material as a scene file writes it (docs/scene-format.md): a dict, its JSON text,
        or keywords, e.g. add_material(type="lambertian", albedo=(0.7, 0.2, 0.2)).  Returns its
        id for the shapes."""
        return _c.scene_add_material(self._cap, _json_text("add_material", material, fields))

    def add_mesh(self, vertices, indices, normals=None, uvs=None, material=0):
        """A triangle mesh: vertices N x 3, indices M x 3 (numpy arrays or sequences), optional
        unit vertex normals N x 3 and texture coordinates N x 2."""
        pos, n = _floats(vertices, "vertices", 3)
        idx = _indices(indices, n)
        nrm = None if normals is None else _floats(normals, "normals", 3)[0]
        uv = None if uvs is None else _floats(uvs, "uvs", 2)[0]
        _c.scene_add_mesh(self._cap, pos, idx, nrm, uv, int(material))

    def add_prototype(self, vertices, indices, normals=None, uvs=None, material=0):
        """A mesh placed only by add_instance (one copy in memory however often it is placed);
        returns its id.  Its material may not emit light."""
        pos, n = _floats(vertices, "vertices", 3)
        idx = _indices(indices, n)
        nrm = None if normals is None else _floats(normals, "normals", 3)[0]
        uv = None if uvs is None else _floats(uvs, "uvs", 2)[0]
        return _c.scene_add_mesh(self._cap, pos, idx, nrm, uv, int(material), True)

    def add_instance(self, prototype, matrix):
        """Places a prototype by an affine transform: a 3 x 4 or 4 x 4 matrix (the last row
        [0, 0, 0, 1]), x' = M [x, y, z, 1]."""
        try:
            rows = [[float(v) for v in r] for r in matrix]
        except (TypeError, ValueError):
            raise ValueError("instance: expected a 3 x 4 or 4 x 4 matrix of numbers") from None
        if len(rows) == 4:
            if rows[3] != [0.0, 0.0, 0.0, 1.0]:
                raise ValueError("instance: the last row must be [0, 0, 0, 1] (affine)")
            rows = rows[:3]
        if len(rows) != 3 or any(len(r) != 4 for r in rows):
            raise ValueError("instance: expected a 3 x 4 or 4 x 4 matrix")
        _c.scene_add_instance(self._cap, int(prototype), [v for r in rows for v in r])

    def add_light(self, light=None, **fields):
        """A point, spot or directional light as a scene file writes it: a dict, its JSON text
        or keywords, e.g. add_light(type="point_light", position=(0, 3, 0),
        intensity=(10, 10, 10))."""
        _c.scene_add_light(self._cap, _json_text("add_light", light, fields))

    def add_sphere(self, center, radius, material=0):
        _c.scene_add_sphere(self._cap, center, float(radius), int(material))

    def add_quad(self, q, u, v, material=0):
        """The parallelogram q + a u + b v, a, b in [0, 1]."""
        _c.scene_add_quad(self._cap, q, u, v, int(material))

    def set_camera(self, from_, at, up=(0, 1, 0), vfov=40.0, aperture=0.0, focus_distance=0.0):
        _c.scene_set_camera(self._cap, from_, at, up, float(vfov), float(aperture),
                            float(focus_distance))

    def set_background(self, rgb):
        _c.scene_set_background(self._cap, rgb)

    def set_image_size(self, width, height):
        _c.scene_set_image_size(self._cap, int(width), int(height))

    @property
    def counts(self):
        """(spheres, quads, triangles, materials)"""
        return _c.scene_counts(self._cap)

    def __repr__(self):
        return "<raystream.Scene %d spheres, %d quads, %d triangles, %d materials>" % self.counts


def load(path):
    """A scene from what `raystream render` takes as SCENE: "builtin:NAME", a .json scene file,
    a .gltf/.glb file."""
    return Scene(_c.scene_load(_path(path)))


def load_json(scene, base_dir=None):
    """A scene from a JSON description (docs/scene-format.md): a dict or its text; file names in
    it are found from base_dir."""
    if not isinstance(scene, str):
        scene = _json.dumps(scene)
    return Scene(_c.scene_from_json(scene, None if base_dir is None else _path(base_dir)))


def _option_text(name, value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (list, tuple)):
        return ",".join(_option_text(name, v) for v in value)
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, (int, str)):
        return str(value)
    import os
    if isinstance(value, os.PathLike):
        return _path(value)
    raise ValueError("%s: %r is not a number, text or list" % (name, value))


def render(scene, progress=None, **options):
    """Renders `scene` (a Scene, or anything `raystream render` takes as SCENE) with the
    command's options as keywords (spp=16, max_depth=8, devices="cpu", aov=["albedo"], ...).
    `progress(fraction)` is called a few times a second; returning False stops the render (the
    image then has .cancelled set)."""
    if progress is not None and not callable(progress):
        raise ValueError("progress must be callable")
    opts = [(k, _option_text(k, v)) for k, v in options.items() if v is not None]
    if isinstance(scene, Scene):
        target = scene._cap
    elif isinstance(scene, (str, bytes)) or hasattr(scene, "__fspath__"):
        target = _path(scene)
    else:
        raise ValueError("scene: expected a raystream.Scene, builtin:NAME or a file, not %r"
                         % (scene,))
    return Image(_c.render(target, opts, progress))


def read_image(path):
    """An image file (.exr, .pfm, .hdr, .png, ...) as an Image of linear RGB."""
    return Image(_c.image_read(_path(path)))
