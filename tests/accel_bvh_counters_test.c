/* tests/accel_bvh_counters_test.c — the traversal counters (RS_COUNTERS, compiled into this
 * translation unit only) count what traversal does, on trees small enough to count by hand. */
#define RS_COUNTERS 1

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "accel/bvh.h"
#include "test_rand.h"

static rs_tri tri_at(float x)
{
    rs_tri t;
    t.v0 = rs_v3(x, 0, 0);
    t.v1 = rs_v3(x + 1, 0, 0);
    t.v2 = rs_v3(x, 1, 0);
    return t;
}

static rs_trace_counters delta(rs_trace_counters a)
{
    rs_trace_counters d;
    d.rays = rs_counters.rays - a.rays;
    d.nodes = rs_counters.nodes - a.nodes;
    d.box_tests = rs_counters.box_tests - a.box_tests;
    d.prim_tests = rs_counters.prim_tests - a.prim_tests;
    return d;
}

static void test_one_leaf(void **state)
{
    rs_tri t = tri_at(0);
    rs_geom g;
    rs_bvh *b;
    rs_bvh_view v;
    rs_hit h;
    rs_trace_counters before, d;
    (void)state;
    memset(&g, 0, sizeof g);
    g.tris = &t;
    g.n_tris = 1;
    assert_int_equal(rs_bvh_build(&g, NULL, &b), RS_OK);
    v = rs_bvh_view_of(b);
    before = rs_counters;
    assert_true(rs_bvh_closest(&v, &g, mk_ray(rs_v3(.2f, .2f, 1), rs_v3(0, 0, -1), 0, 10), &h));
    d = delta(before);
    /* the root box, the root (a leaf), its triangle */
    assert_int_equal(d.rays, 1);
    assert_int_equal(d.box_tests, 1);
    assert_int_equal(d.nodes, 1);
    assert_int_equal(d.prim_tests, 1);
    before = rs_counters;
    assert_false(rs_bvh_closest(&v, &g, mk_ray(rs_v3(5, 5, 1), rs_v3(0, 0, -1), 0, 10), &h));
    d = delta(before);
    /* the root box misses: nothing else is touched */
    assert_int_equal(d.box_tests, 1);
    assert_int_equal(d.nodes, 0);
    assert_int_equal(d.prim_tests, 0);
    rs_bvh_destroy(b);
}

static void test_two_leaves(void **state)
{
    rs_tri t[2];
    rs_geom g;
    rs_bvh *b;
    rs_bvh_build_opts o;
    rs_bvh_view v;
    rs_hit h;
    rs_trace_counters before, d;
    (void)state;
    t[0] = tri_at(0);
    t[1] = tri_at(10);
    memset(&g, 0, sizeof g);
    g.tris = t;
    g.n_tris = 2;
    memset(&o, 0, sizeof o);
    o.max_leaf = 1;
    assert_int_equal(rs_bvh_build(&g, &o, &b), RS_OK);
    assert_int_equal(b->n_nodes, 3u);
    v = rs_bvh_view_of(b);
    before = rs_counters;
    assert_true(rs_bvh_closest(&v, &g, mk_ray(rs_v3(.2f, .2f, 1), rs_v3(0, 0, -1), 0, 10), &h));
    d = delta(before);
    /* root box; the root; both children's boxes; the one leaf hit; its triangle */
    assert_int_equal(d.box_tests, 3);
    assert_int_equal(d.nodes, 2);
    assert_int_equal(d.prim_tests, 1);
    before = rs_counters;
    assert_true(rs_bvh_occluded(&v, &g, mk_ray(rs_v3(10.2f, .2f, 1), rs_v3(0, 0, -1), 0, 10)));
    d = delta(before);
    /* any-hit: the root, then both children are pushed; the first popped (left) misses, the
     * right is hit and its triangle ends the search */
    assert_int_equal(d.rays, 1);
    assert_int_equal(d.box_tests, 3);
    assert_int_equal(d.nodes, 2);
    assert_int_equal(d.prim_tests, 1);
    rs_bvh_destroy(b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_one_leaf),
                                       cmocka_unit_test(test_two_leaves)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
