/* The binned-SAH builder: the exact node count, the structure invariants
 * (every item once, boxes containing their children and items, depth cap),
 * determinism, empty items, refit, SAH cost and progress reports. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bvh/bvh.h"
#include "core/arena.h"
#include "core/threads.h"

#if defined(RANGECAST_WITH_THREADS)
#include <pthread.h>
#endif

/* ---- helpers --------------------------------------------------------------- */

/* SAH cost of a tree: traversal step 1, item test 1, areas relative to the
 * root's (empty boxes count 0). Only tests read it, so it lives here rather
 * than in the static core. */
static double half_area(const float lo[3], const float hi[3])
{
    if (!(lo[0] <= hi[0] && lo[1] <= hi[1] && lo[2] <= hi[2])) return 0.0;
    return (double)(hi[0] - lo[0]) * (hi[1] - lo[1]) + (double)(hi[1] - lo[1]) * (hi[2] - lo[2]) +
           (double)(hi[2] - lo[2]) * (hi[0] - lo[0]);
}

static double sah_cost(const rc__bvh *bvh)
{
    double root, sum = 0.0;
    uint32_t i;
    if (bvh->node_count == 0) return 0.0;
    root = half_area(bvh->nodes[0].bmin, bvh->nodes[0].bmax);
    for (i = 0; i < bvh->node_count; ++i) {
        const rc__bvh_node *n = &bvh->nodes[i];
        const double a = half_area(n->bmin, n->bmax);
        sum += n->count ? a * (double)n->count : a;
    }
    return root > 0.0 ? sum / root : sum;
}

static uint64_t rng_state;

static uint32_t rng_u32(void)
{
    /* xorshift64* */
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (uint32_t)((rng_state * 2685821657736338717ull) >> 32);
}

static float rng_float(float lo, float hi)
{
    return lo + (hi - lo) * (float)(rng_u32() >> 8) * (1.0f / 16777216.0f);
}

enum shape {
    SHAPE_RANDOM,      /* random boxes of random sizes */
    SHAPE_SAME,        /* every box identical: all centroids coincide */
    SHAPE_LINE,        /* unit boxes along x */
    SHAPE_EXPONENTIAL, /* positions 1.5^i: a degenerate SAH would make a list */
    SHAPE_WITH_EMPTY,  /* random boxes, every third one empty (min > max) */
    SHAPE_ALL_EMPTY,
    SHAPE_COUNT
};

static int box_empty(const rc__aabb *b)
{
    return !(b->min[0] <= b->max[0] && b->min[1] <= b->max[1] && b->min[2] <= b->max[2]);
}

static void make_boxes(rc__aabb *b, uint32_t n, enum shape shape)
{
    uint32_t i;
    int k;
    for (i = 0; i < n; ++i) {
        switch (shape) {
        case SHAPE_SAME:
            for (k = 0; k < 3; ++k) {
                b[i].min[k] = 1.0f;
                b[i].max[k] = 2.0f;
            }
            break;
        case SHAPE_LINE:
            b[i].min[0] = (float)i;
            b[i].max[0] = (float)i + 1.0f;
            b[i].min[1] = b[i].min[2] = 0.0f;
            b[i].max[1] = b[i].max[2] = 1.0f;
            break;
        case SHAPE_EXPONENTIAL: {
            float x = powf(1.5f, (float)(i % 200)) * (1.0f + (float)(i / 200));
            b[i].min[0] = x;
            b[i].max[0] = x * 1.01f;
            b[i].min[1] = b[i].min[2] = 0.0f;
            b[i].max[1] = b[i].max[2] = 1.0f;
            break;
        }
        case SHAPE_ALL_EMPTY:
            for (k = 0; k < 3; ++k) {
                b[i].min[k] = INFINITY;
                b[i].max[k] = -INFINITY;
            }
            break;
        case SHAPE_WITH_EMPTY:
        case SHAPE_RANDOM:
        default:
            for (k = 0; k < 3; ++k) {
                float c = rng_float(-100.0f, 100.0f), h = rng_float(0.0f, 3.0f);
                b[i].min[k] = c - h;
                b[i].max[k] = c + h;
            }
            if (shape == SHAPE_WITH_EMPTY && i % 3 == 1) {
                /* an inverted box (not the canonical +inf/-inf one) */
                b[i].min[0] = 50.0f;
                b[i].max[0] = -50.0f;
            }
            break;
        }
    }
}

typedef struct built {
    rc__bvh bvh;
    void *scratch;
} built;

/* Every buffer is allocated at its exact size so ASan catches overruns. */
static void build(built *out, const rc__aabb *boxes, uint32_t n, uint32_t leaf, unsigned char fill)
{
    uint32_t nodes = rc__bvh_node_count(n, leaf);
    size_t sb = rc__bvh_build_scratch_bytes(n);
    memset(out, 0, sizeof *out);
    out->bvh.nodes = malloc(nodes ? nodes * sizeof(rc__bvh_node) : 1);
    out->bvh.refs = malloc(n ? n * sizeof(uint32_t) : 1);
    out->scratch = malloc(sb ? sb : 1);
    assert_non_null(out->bvh.nodes);
    assert_non_null(out->bvh.refs);
    assert_non_null(out->scratch);
    memset(out->scratch, fill, sb);
    memset(out->bvh.nodes, fill, nodes * sizeof(rc__bvh_node));
    memset(out->bvh.refs, fill, n * sizeof(uint32_t));
    rc__bvh_build(boxes, n, leaf, out->scratch, &out->bvh, NULL, NULL);
}

static void release(built *b)
{
    free(b->bvh.nodes);
    free(b->bvh.refs);
    free(b->scratch);
}

static int box_contains(const float *omin, const float *omax, const float *imin, const float *imax)
{
    int k;
    for (k = 0; k < 3; ++k) {
        if (!(omin[k] <= imin[k] && imax[k] <= omax[k])) return 0;
    }
    return 1;
}

/* Walks the whole tree and checks every invariant of bvh.h; returns the
 * depth of the deepest leaf. */
static uint32_t check_tree(const rc__bvh *bvh, const rc__aabb *boxes, uint32_t n, uint32_t leaf)
{
    uint32_t expected_nodes = n ? (uint32_t)(2 * ((n + leaf - 1) / leaf) - 1) : 0;
    uint32_t *seen_node, *seen_item, *stack, *depth;
    uint32_t sp = 0, visited = 0, leaves = 0, partial = 0, covered = 0, i, max_depth = 0;

    assert_int_equal(bvh->node_count, expected_nodes);
    assert_int_equal(rc__bvh_node_count(n, leaf), expected_nodes);
    assert_int_equal(bvh->item_count, n);
    assert_int_equal(bvh->leaf_size, leaf);
    if (n == 0) return 0;

    seen_node = calloc(bvh->node_count, sizeof *seen_node);
    seen_item = calloc(n, sizeof *seen_item);
    stack = malloc(sizeof *stack * (bvh->node_count + 1));
    depth = malloc(sizeof *depth * (bvh->node_count + 1));
    stack[sp] = 0;
    depth[sp++] = 0;
    while (sp) {
        const uint32_t ni = stack[--sp], d = depth[sp];
        const rc__bvh_node *nd = &bvh->nodes[ni];
        assert_true(ni < bvh->node_count);
        assert_int_equal(seen_node[ni], 0);
        seen_node[ni] = 1;
        ++visited;
        assert_true(d <= RC__BVH_MAX_DEPTH);
        if (nd->count == 0) {
            uint32_t c;
            /* children adjacent and after their parent */
            assert_true(nd->index > ni);
            assert_true(nd->index + 1 < bvh->node_count);
            for (c = nd->index; c <= nd->index + 1; ++c) {
                const rc__bvh_node *ch = &bvh->nodes[c];
                int empty = !(ch->bmin[0] <= ch->bmax[0] && ch->bmin[1] <= ch->bmax[1] &&
                              ch->bmin[2] <= ch->bmax[2]);
                if (!empty) assert_true(box_contains(nd->bmin, nd->bmax, ch->bmin, ch->bmax));
                stack[sp] = c;
                depth[sp++] = d + 1;
            }
        } else {
            uint32_t j;
            ++leaves;
            if (d > max_depth) max_depth = d;
            assert_true(nd->count <= leaf);
            if (nd->count != leaf) ++partial;
            assert_true(nd->index + nd->count <= n);
            covered += nd->count;
            for (j = nd->index; j < nd->index + nd->count; ++j) {
                const uint32_t item = bvh->refs[j];
                assert_true(item < n);
                assert_int_equal(seen_item[item], 0);
                seen_item[item] = 1;
                if (!box_empty(&boxes[item]))
                    assert_true(box_contains(nd->bmin, nd->bmax, boxes[item].min, boxes[item].max));
            }
        }
    }
    assert_int_equal(visited, bvh->node_count);
    assert_int_equal(leaves, (n + leaf - 1) / leaf);
    assert_int_equal(partial, n % leaf ? 1u : 0u);
    assert_int_equal(covered, n);
    for (i = 0; i < n; ++i) assert_int_equal(seen_item[i], 1);
    /* leaf ranges of refs are disjoint: covered == n and every item seen once */
    free(seen_node);
    free(seen_item);
    free(stack);
    free(depth);
    return max_depth;
}

/* ---- tests ----------------------------------------------------------------- */

static void test_node_count_formula(void **state)
{
    (void)state;
    assert_int_equal(rc__bvh_node_count(0, 4), 0);
    assert_int_equal(rc__bvh_node_count(1, 4), 1);
    assert_int_equal(rc__bvh_node_count(4, 4), 1);
    assert_int_equal(rc__bvh_node_count(5, 4), 3);
    assert_int_equal(rc__bvh_node_count(8, 4), 3);
    assert_int_equal(rc__bvh_node_count(9, 4), 5);
    assert_int_equal(rc__bvh_node_count(1000000, 4), 499999);
    assert_int_equal(rc__bvh_node_count(1, 1), 1);
    assert_int_equal(rc__bvh_node_count(2, 1), 3);
    assert_int_equal(rc__bvh_node_count(10000000, 1), 19999999);
    assert_int_equal(rc__bvh_node_count(10000001, 4), 5000001);
}

/* Many counts, leaf sizes and shapes: the node count is exact and every
 * invariant holds whatever the geometry. */
static void test_structure_many_sizes(void **state)
{
    static const uint32_t leaves[] = {1, 2, 3, 4, 7};
    static const uint32_t extra[] = {500, 1000, 1023, 1024, 1025, 4097, 20000};
    const uint32_t small = 70, count_sizes = small + (uint32_t)(sizeof extra / sizeof extra[0]);
    uint32_t si, li;
    int shape;
    (void)state;
    rng_state = 12345;
    for (shape = 0; shape < SHAPE_COUNT; ++shape) {
        for (li = 0; li < sizeof leaves / sizeof leaves[0]; ++li) {
            for (si = 0; si < count_sizes; ++si) {
                const uint32_t n = si < small ? si + 1 : extra[si - small];
                rc__aabb *boxes = malloc(sizeof *boxes * n);
                built b;
                make_boxes(boxes, n, (enum shape)shape);
                build(&b, boxes, n, leaves[li], 0xAB);
                check_tree(&b.bvh, boxes, n, leaves[li]);
                release(&b);
                free(boxes);
            }
        }
    }
}

static void test_empty_input(void **state)
{
    rc__bvh bvh;
    rc__bvh_node node;
    uint32_t ref;
    (void)state;
    memset(&bvh, 0x5A, sizeof bvh);
    bvh.nodes = &node;
    bvh.refs = &ref;
    rc__bvh_build(NULL, 0, 4, NULL, &bvh, NULL, NULL);
    assert_int_equal(bvh.node_count, 0);
    assert_int_equal(bvh.item_count, 0);
    assert_true(sah_cost(&bvh) == 0.0);
}

static void test_deterministic(void **state)
{
    const uint32_t n = 30000;
    rc__aabb *boxes = malloc(sizeof *boxes * n);
    int shape;
    (void)state;
    for (shape = 0; shape < SHAPE_COUNT; ++shape) {
        built a, b;
        rng_state = 777 + (uint64_t)shape;
        make_boxes(boxes, n, (enum shape)shape);
        build(&a, boxes, n, 4, 0x00);
        build(&b, boxes, n, 4, 0xFF); /* different garbage in scratch and outputs */
        assert_int_equal(a.bvh.node_count, b.bvh.node_count);
        assert_memory_equal(a.bvh.nodes, b.bvh.nodes, a.bvh.node_count * sizeof(rc__bvh_node));
        assert_memory_equal(a.bvh.refs, b.bvh.refs, n * sizeof(uint32_t));
        release(&a);
        release(&b);
    }
    free(boxes);
}

/* Empty items never enlarge a node: a tree over only empty items has empty
 * boxes everywhere, and mixed in, the root is the union of the others. */
static void test_empty_items_do_not_grow_bounds(void **state)
{
    const uint32_t n = 999;
    rc__aabb *boxes = malloc(sizeof *boxes * n);
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    built b;
    uint32_t i;
    int k;
    (void)state;
    rng_state = 99;
    make_boxes(boxes, n, SHAPE_WITH_EMPTY);
    /* some NaN boxes too: treated as empty */
    boxes[5].min[1] = NAN;
    boxes[8].max[2] = NAN;
    for (i = 0; i < n; ++i) {
        if (box_empty(&boxes[i])) continue;
        for (k = 0; k < 3; ++k) {
            lo[k] = fminf(lo[k], boxes[i].min[k]);
            hi[k] = fmaxf(hi[k], boxes[i].max[k]);
        }
    }
    build(&b, boxes, n, 4, 0);
    check_tree(&b.bvh, boxes, n, 4);
    for (k = 0; k < 3; ++k) {
        assert_true(b.bvh.nodes[0].bmin[k] == lo[k]);
        assert_true(b.bvh.nodes[0].bmax[k] == hi[k]);
    }
    release(&b);

    make_boxes(boxes, n, SHAPE_ALL_EMPTY);
    build(&b, boxes, n, 4, 0);
    check_tree(&b.bvh, boxes, n, 4);
    for (i = 0; i < b.bvh.node_count; ++i) assert_true(b.bvh.nodes[i].bmin[0] > b.bvh.nodes[i].bmax[0]);
    release(&b);
    free(boxes);
}

/* Points at x = -2^k: bin 0 holds only the farthest point, and with zero
 * areas every split costs the same, so the SAH alone would peel one leaf off
 * per level (a list). The cap bounds the depth at RC__BVH_MAX_DEPTH. */
static uint32_t build_peeling(uint32_t n, uint32_t leaf)
{
    rc__aabb *boxes = malloc(sizeof *boxes * n);
    built b;
    uint32_t i, depth;
    for (i = 0; i < n; ++i) {
        boxes[i].min[0] = boxes[i].max[0] = -ldexpf(1.0f, (int)(i / leaf) - 100);
        boxes[i].min[1] = boxes[i].min[2] = boxes[i].max[1] = boxes[i].max[2] = 0.0f;
    }
    build(&b, boxes, n, leaf, 0);
    depth = check_tree(&b.bvh, boxes, n, leaf); /* asserts depth <= RC__BVH_MAX_DEPTH */
    release(&b);
    free(boxes);
    return depth;
}

static void test_depth_cap(void **state)
{
    (void)state;
    assert_int_equal(build_peeling(60, 1), 59); /* below the cap: the list */
    assert_int_equal(build_peeling(200, 1), RC__BVH_MAX_DEPTH);
    assert_int_equal(build_peeling(800, 4), RC__BVH_MAX_DEPTH);
}

/* The SAH separates two distant clusters at the root; on unit boxes in a row
 * its cost is that of a balanced tree (a list would cost ~n/2). */
static void test_sah_quality(void **state)
{
    const uint32_t n = 4000;
    rc__aabb *boxes = malloc(sizeof *boxes * n);
    built b;
    uint32_t i;
    int k;
    double cost;
    (void)state;
    rng_state = 4242;
    for (i = 0; i < n; ++i) {
        float off = i % 2 ? 1000.0f : -1000.0f;
        for (k = 0; k < 3; ++k) {
            float c = rng_float(-10.0f, 10.0f) + (k == 1 ? off : 0.0f);
            boxes[i].min[k] = c - 0.5f;
            boxes[i].max[k] = c + 0.5f;
        }
    }
    build(&b, boxes, n, 4, 0);
    check_tree(&b.bvh, boxes, n, 4);
    {
        const rc__bvh_node *l = &b.bvh.nodes[b.bvh.nodes[0].index], *r = l + 1;
        /* the two children do not overlap in y */
        assert_true(l->bmax[1] < r->bmin[1] || r->bmax[1] < l->bmin[1]);
    }
    release(&b);

    /* 1024 unit boxes along x, leaf size 1: a balanced tree has 11 levels,
     * each of total area ~ the root's, plus leaves of 3/2049 each: ~13.5 */
    make_boxes(boxes, 1024, SHAPE_LINE);
    build(&b, boxes, 1024, 1, 0);
    cost = sah_cost(&b.bvh);
    assert_true(cost > 11.0 && cost < 15.0);
    release(&b);

    /* a single leaf: the cost is exactly its item count */
    build(&b, boxes, 3, 4, 0);
    assert_true(sah_cost(&b.bvh) == 3.0);
    release(&b);
    free(boxes);
}

/* Refit after moving items keeps every box containing its content; refit with
 * the original bounds reproduces the built boxes exactly. */
static void test_refit(void **state)
{
    const uint32_t n = 20000;
    rc__aabb *boxes = malloc(sizeof *boxes * n);
    rc__bvh_node *copy;
    built b;
    uint32_t i;
    int k;
    (void)state;
    rng_state = 31337;
    make_boxes(boxes, n, SHAPE_WITH_EMPTY);
    build(&b, boxes, n, 4, 0);
    copy = malloc(sizeof *copy * b.bvh.node_count);
    memcpy(copy, b.bvh.nodes, sizeof *copy * b.bvh.node_count);
    rc__bvh_refit(&b.bvh, boxes);
    assert_memory_equal(copy, b.bvh.nodes, sizeof *copy * b.bvh.node_count);

    for (i = 0; i < n; ++i) {
        if (box_empty(&boxes[i])) continue;
        for (k = 0; k < 3; ++k) {
            float d = rng_float(-30.0f, 30.0f);
            boxes[i].min[k] += d;
            boxes[i].max[k] += d + rng_float(0.0f, 2.0f);
        }
    }
    rc__bvh_refit(&b.bvh, boxes);
    check_tree(&b.bvh, boxes, n, 4);
    /* the structure did not change */
    for (i = 0; i < b.bvh.node_count; ++i) {
        assert_int_equal(copy[i].index, b.bvh.nodes[i].index);
        assert_int_equal(copy[i].count, b.bvh.nodes[i].count);
    }
    /* boxes are tight: the root is exactly the union of non-empty items */
    for (k = 0; k < 3; ++k) {
        float lo = INFINITY, hi = -INFINITY;
        for (i = 0; i < n; ++i) {
            if (box_empty(&boxes[i])) continue;
            lo = fminf(lo, boxes[i].min[k]);
            hi = fmaxf(hi, boxes[i].max[k]);
        }
        assert_true(b.bvh.nodes[0].bmin[k] == lo);
        assert_true(b.bvh.nodes[0].bmax[k] == hi);
    }
    free(copy);
    release(&b);
    free(boxes);
}

typedef struct progress_log {
    int calls;
    int bad_stage;
    double last;
    int decreasing;
} progress_log;

static int on_progress(void *user, const char *stage, double fraction)
{
    progress_log *p = user;
    if (strcmp(stage, "bvh build") != 0) p->bad_stage = 1;
    if (fraction < p->last || fraction < 0.0 || fraction > 1.0) p->decreasing = 1;
    p->last = fraction;
    p->calls++;
    return 1;
}

static void test_progress(void **state)
{
    const uint32_t n = 100000;
    rc__aabb *boxes = malloc(sizeof *boxes * n);
    progress_log log;
    built b, c;
    (void)state;
    rng_state = 5;
    make_boxes(boxes, n, SHAPE_RANDOM);
    build(&c, boxes, n, 4, 0); /* without callback, for comparison */
    memset(&log, 0, sizeof log);
    b.bvh.nodes = malloc(sizeof(rc__bvh_node) * rc__bvh_node_count(n, 4));
    b.bvh.refs = malloc(sizeof(uint32_t) * n);
    b.scratch = malloc(rc__bvh_build_scratch_bytes(n));
    rc__bvh_build(boxes, n, 4, b.scratch, &b.bvh, on_progress, &log);
    assert_int_equal(log.bad_stage, 0);
    assert_int_equal(log.decreasing, 0);
    assert_true(log.calls >= 5 && log.calls <= 40);
    assert_true(log.last == 1.0);
    /* the callback does not change the result */
    assert_memory_equal(b.bvh.nodes, c.bvh.nodes, sizeof(rc__bvh_node) * b.bvh.node_count);
    release(&b);
    release(&c);
    free(boxes);
}

/* The build spread over a pool writes the serial build's tree bit for bit,
 * for every thread count, shape and leaf size, and reports progress in order,
 * on the calling thread only, ending at 1. */
typedef struct mt_progress {
    progress_log log;
#if defined(RANGECAST_WITH_THREADS)
    pthread_t caller;
#endif
    int foreign_thread;
} mt_progress;

static int on_progress_mt(void *user, const char *stage, double fraction)
{
    mt_progress *p = user;
#if defined(RANGECAST_WITH_THREADS)
    if (!pthread_equal(pthread_self(), p->caller)) p->foreign_thread = 1;
#endif
    return on_progress(&p->log, stage, fraction);
}

static void test_parallel_same_tree(void **state)
{
    static const enum shape shapes[] = {SHAPE_RANDOM, SHAPE_WITH_EMPTY, SHAPE_SAME, SHAPE_EXPONENTIAL, SHAPE_LINE};
    static const uint32_t leaves[] = {4, 1};
    const uint32_t n = 70001; /* odd: one leaf holds the remainder */
    rc__aabb *boxes = malloc(sizeof *boxes * n);
    uint32_t si, li, threads;
    (void)state;
    assert_non_null(boxes);
    for (si = 0; si < sizeof shapes / sizeof shapes[0]; ++si) {
        rng_state = 77 + si;
        make_boxes(boxes, n, shapes[si]);
        for (li = 0; li < 2; ++li) {
            built serial;
            build(&serial, boxes, n, leaves[li], 0);
            for (threads = 2; threads <= 4; ++threads) {
                const size_t bytes = rc__pool_memory(threads) + 4096;
                void *block = malloc(bytes);
                rc__arena arena;
                rc__pool *pool = NULL;
                built b;
                mt_progress prog;
                const uint32_t nodes = rc__bvh_node_count(n, leaves[li]);
                assert_non_null(block);
                rc__arena_init(&arena, block, bytes);
                assert_int_equal(rc__pool_create(&arena, threads, &pool), RC_OK);
                memset(&prog, 0, sizeof prog);
#if defined(RANGECAST_WITH_THREADS)
                prog.caller = pthread_self();
#endif
                b.bvh.nodes = malloc(sizeof(rc__bvh_node) * nodes);
                b.bvh.refs = malloc(sizeof(uint32_t) * n);
                b.scratch = malloc(rc__bvh_build_scratch_bytes(n));
                assert_non_null(b.bvh.nodes);
                assert_non_null(b.bvh.refs);
                assert_non_null(b.scratch);
                memset(b.bvh.nodes, 0x5a, sizeof(rc__bvh_node) * nodes);
                rc__bvh_build_mt(boxes, n, leaves[li], b.scratch, &b.bvh, pool, on_progress_mt, &prog);
                assert_int_equal(b.bvh.node_count, serial.bvh.node_count);
                assert_memory_equal(b.bvh.nodes, serial.bvh.nodes, sizeof(rc__bvh_node) * nodes);
                assert_memory_equal(b.bvh.refs, serial.bvh.refs, sizeof(uint32_t) * n);
                assert_int_equal(prog.log.bad_stage, 0);
                assert_int_equal(prog.log.decreasing, 0);
                assert_int_equal(prog.foreign_thread, 0);
                assert_true(prog.log.calls >= 2);
                assert_true(prog.log.last == 1.0);
                release(&b);
                rc__pool_destroy(&arena, pool);
                free(block);
            }
            check_tree(&serial.bvh, boxes, n, leaves[li]);
            release(&serial);
        }
    }
    free(boxes);
}

/* A large build: exact sizes, the invariants, and a sensible depth. */
static void test_large(void **state)
{
    const uint32_t n = 300000;
    rc__aabb *boxes = malloc(sizeof *boxes * n);
    built b;
    (void)state;
    rng_state = 2024;
    make_boxes(boxes, n, SHAPE_RANDOM);
    build(&b, boxes, n, 4, 0x11);
    check_tree(&b.bvh, boxes, n, 4);
    release(&b);
    free(boxes);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_node_count_formula),
        cmocka_unit_test(test_structure_many_sizes),
        cmocka_unit_test(test_empty_input),
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_empty_items_do_not_grow_bounds),
        cmocka_unit_test(test_depth_cap),
        cmocka_unit_test(test_sah_quality),
        cmocka_unit_test(test_refit),
        cmocka_unit_test(test_progress),
        cmocka_unit_test(test_parallel_same_tree),
        cmocka_unit_test(test_large),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
