/* The binned-SAH BVH builder, refit and SAH cost (see bvh.h for the layout).
 *
 * Top-down, one node at a time, with an explicit stack (no recursion):
 *   1. bin the node's items by centroid into up to RC__BINS bins on each of the
 *      three axes (one pass: bin counts and bin bounds);
 *   2. pick the axis and bin boundary of least SAH cost, costing each side by
 *      ceil(count / leaf_size) leaves (items are intersected a leaf at a time);
 *   3. round the left count k to a multiple of leaf_size (clamped so both sides
 *      are non-empty): this is what makes every leaf full but one, and the node
 *      count a function of the item count alone;
 *   4. put exactly k items left: a three-way partition by bin around the bin
 *      holding the k-th item, then a quickselect inside that bin only, keyed by
 *      (centroid on the axis, item index) so the result is deterministic. The
 *      partition pass also gathers both children's bounds and centroid bounds,
 *      so no other pass over the items is needed.
 * Node numbers are fixed by leaf counts alone: a node's children are the pair
 * at its descendants' base, the left child's descendants follow the pair and
 * the right child's follow those (rc__split_task). Every subtree thus owns a
 * node range known before it is built, which lets rc__bvh_build_mt build the
 * subtrees below the top levels on the context's threads and still write the
 * serial build's tree, bit for bit.
 * Items live in scratch as 32-byte records (box + index) that are moved, so
 * every pass reads memory sequentially; refs are written from them at the end.
 * Centroids are kept doubled (min + max), which is exact enough and saves the
 * halving everywhere.
 *
 * Depth is capped at RC__BVH_MAX_DEPTH (traversal stacks have that many
 * entries): a split that would leave a child unable to fit under the cap with a
 * balanced subtree is replaced by a balanced split.
 *
 * Empty item boxes (min > max on some axis, or NaN) are stored as the canonical
 * empty box (+inf, -inf), which min/max leave without effect, so they never
 * grow a node. Their centroid is NaN: it is left out of centroid bounds, falls
 * in the last bin, and the quickselect orders it by item index; they end up in
 * some leaf like any item. */
#include "bvh/bvh.h"

#include <math.h>

#define RC__BINS 32u
#define RC__STACK 72u /* > log2(2^32) + 1: the smaller child is processed first */

typedef struct rc__build_item {
    float lo[3];
    uint32_t id;
    float hi[3];
    uint32_t pad;
} rc__build_item;

typedef struct rc__bin {
    float lo[3];
    uint32_t count;
    float hi[3];
    uint32_t pad;
} rc__bin;

typedef struct rc__task {
    uint32_t node;
    uint32_t begin;
    uint32_t end;
    uint32_t depth;
    uint32_t base;  /* first node of its descendants: [base, base + 2 * leaves - 2) */
    uint32_t pad;
    float cmin[3]; /* bounds of the doubled centroids */
    float cmax[3];
} rc__task;

/* Bounds and (doubled) centroid bounds gathered over a set of items. */
typedef struct rc__acc {
    float lo[3], hi[3];
    float clo[3], chi[3];
} rc__acc;

/* a < b ? a : b: with a NaN in a, gives b. */
static inline float rc__fmin(float a, float b) { return a < b ? a : b; }
static inline float rc__fmax(float a, float b) { return a > b ? a : b; }

static void rc__acc_reset(rc__acc *a)
{
    a->lo[0] = a->lo[1] = a->lo[2] = INFINITY;
    a->hi[0] = a->hi[1] = a->hi[2] = -INFINITY;
    a->clo[0] = a->clo[1] = a->clo[2] = INFINITY;
    a->chi[0] = a->chi[1] = a->chi[2] = -INFINITY;
}

/* Doubled centroid on one axis (NaN for an empty item). */
static inline float rc__centroid2(const rc__build_item *it, int axis)
{
    return it->lo[axis] + it->hi[axis];
}

static inline void rc__acc_add(rc__acc *a, const rc__build_item *it)
{
    const float c0 = it->lo[0] + it->hi[0], c1 = it->lo[1] + it->hi[1], c2 = it->lo[2] + it->hi[2];
    /* the new value first: a NaN centroid leaves the bounds alone */
    a->clo[0] = rc__fmin(c0, a->clo[0]);
    a->clo[1] = rc__fmin(c1, a->clo[1]);
    a->clo[2] = rc__fmin(c2, a->clo[2]);
    a->chi[0] = rc__fmax(c0, a->chi[0]);
    a->chi[1] = rc__fmax(c1, a->chi[1]);
    a->chi[2] = rc__fmax(c2, a->chi[2]);
    a->lo[0] = rc__fmin(it->lo[0], a->lo[0]);
    a->lo[1] = rc__fmin(it->lo[1], a->lo[1]);
    a->lo[2] = rc__fmin(it->lo[2], a->lo[2]);
    a->hi[0] = rc__fmax(it->hi[0], a->hi[0]);
    a->hi[1] = rc__fmax(it->hi[1], a->hi[1]);
    a->hi[2] = rc__fmax(it->hi[2], a->hi[2]);
}

static inline int rc__box_empty(const float lo[3], const float hi[3])
{
    return !(lo[0] <= hi[0] && lo[1] <= hi[1] && lo[2] <= hi[2]);
}

/* Half the surface area; 0 for an empty box. */
static inline float rc__half_area(const float lo[3], const float hi[3])
{
    float dx, dy, dz;
    if (rc__box_empty(lo, hi)) return 0.0f;
    dx = hi[0] - lo[0];
    dy = hi[1] - lo[1];
    dz = hi[2] - lo[2];
    return dx * dy + dy * dz + dz * dx;
}

uint32_t rc__bvh_node_count(uint32_t items, uint32_t leaf_size)
{
    uint64_t leaves;
    if (items == 0) return 0;
    if (leaf_size == 0) leaf_size = 1;
    leaves = ((uint64_t)items + leaf_size - 1) / leaf_size;
    if (2 * leaves - 1 > UINT32_MAX) return UINT32_MAX; /* callers must refuse such sizes */
    return (uint32_t)(2 * leaves - 1);
}

size_t rc__bvh_build_scratch_bytes(uint32_t items)
{
    return (size_t)items * sizeof(rc__build_item);
}

/* Bin of doubled centroid c: the same float operations in every pass, clamped
 * so that NaN or rounding cannot leave [0, nb). */
static inline uint32_t rc__bin_of(float c, float cmin, float scale, float last)
{
    float f = (c - cmin) * scale;
    f = f < last ? f : last; /* NaN -> last */
    f = f > 0.0f ? f : 0.0f;
    return (uint32_t)f;
}

/* Key order of the quickselect: centroid on axis, then item index. */
static inline int rc__item_less(const rc__build_item *a, const rc__build_item *b, int axis)
{
    const float ca = rc__centroid2(a, axis), cb = rc__centroid2(b, axis);
    if (ca < cb) return 1;
    if (cb < ca) return 0;
    return a->id < b->id; /* equal (or NaN): the index decides */
}

static inline void rc__swap(rc__build_item *a, rc__build_item *b)
{
    rc__build_item t = *a;
    *a = *b;
    *b = t;
}

/* Rearranges it[0, n) so that it[0, k) are the k smallest by rc__item_less
 * (0 < k < n). Lomuto partitions around a median-of-three pivot: every loop is
 * bounded by the range, so even an inconsistent order (NaN) ends with exactly k
 * items in front. */
static void rc__select(rc__build_item *it, uint32_t n, uint32_t k, int axis)
{
    uint32_t lo = 0, hi = n; /* the k-th smallest lies in [lo, hi) */
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2, last = hi - 1, i, store;
        /* median of three to it[last] */
        if (rc__item_less(&it[mid], &it[lo], axis)) rc__swap(&it[mid], &it[lo]);
        if (rc__item_less(&it[last], &it[lo], axis)) rc__swap(&it[last], &it[lo]);
        if (rc__item_less(&it[mid], &it[last], axis)) rc__swap(&it[mid], &it[last]);
        store = lo;
        for (i = lo; i < last; ++i) {
            if (rc__item_less(&it[i], &it[last], axis)) {
                if (i != store) rc__swap(&it[i], &it[store]);
                ++store;
            }
        }
        rc__swap(&it[store], &it[last]);
        /* it[store] is in its final place */
        if (store == k) return;
        if (store < k) {
            lo = store + 1;
        } else {
            hi = store;
        }
    }
}

static uint32_t rc__ceil_log2(uint64_t x)
{
    uint32_t r = 0;
    while (((uint64_t)1 << r) < x) ++r;
    return r;
}

typedef struct rc__builder {
    rc__build_item *items;
    rc__bvh_node *nodes;
    uint32_t leaf;
    uint32_t placed;
    uint32_t next_report;
    uint32_t report_step;
    uint32_t reported;
    uint32_t total;
    rc_progress_fn progress;
    void *progress_user;
    rc__bin bins[3][RC__BINS];
} rc__builder;

static void rc__set_node_box(rc__bvh_node *n, const rc__acc *a)
{
    n->bmin[0] = a->lo[0];
    n->bmin[1] = a->lo[1];
    n->bmin[2] = a->lo[2];
    n->bmax[0] = a->hi[0];
    n->bmax[1] = a->hi[1];
    n->bmax[2] = a->hi[2];
}

static void rc__make_leaf(rc__builder *b, uint32_t node, uint32_t begin, uint32_t end)
{
    b->nodes[node].index = begin;
    b->nodes[node].count = end - begin;
    b->placed += end - begin;
    if (b->progress && b->placed >= b->next_report) {
        b->progress(b->progress_user, "bvh build", (double)b->placed / (double)b->total);
        b->reported = b->placed;
        b->next_report = (b->placed / b->report_step + 1) * b->report_step;
    }
}

static inline void rc__bin_add(rc__bin *bin, const rc__build_item *p)
{
    bin->count++;
    bin->lo[0] = rc__fmin(p->lo[0], bin->lo[0]);
    bin->lo[1] = rc__fmin(p->lo[1], bin->lo[1]);
    bin->lo[2] = rc__fmin(p->lo[2], bin->lo[2]);
    bin->hi[0] = rc__fmax(p->hi[0], bin->hi[0]);
    bin->hi[1] = rc__fmax(p->hi[1], bin->hi[1]);
    bin->hi[2] = rc__fmax(p->hi[2], bin->hi[2]);
}

static inline void rc__box_grow(float lo[3], float hi[3], const rc__bin *bin)
{
    lo[0] = rc__fmin(bin->lo[0], lo[0]);
    lo[1] = rc__fmin(bin->lo[1], lo[1]);
    lo[2] = rc__fmin(bin->lo[2], lo[2]);
    hi[0] = rc__fmax(bin->hi[0], hi[0]);
    hi[1] = rc__fmax(bin->hi[1], hi[1]);
    hi[2] = rc__fmax(bin->hi[2], hi[2]);
}

/* Chooses the axis and the left count k of a node's split (0 < k < n, k a
 * multiple of leaf_size). Returns the axis; *uses_bins says whether the bins
 * of that axis (b->bins[axis], scale[axis], *nb_out bins) can guide the
 * partition. */
static int rc__choose_split(rc__builder *b, const rc__task *t, float scale[3], uint32_t *nb_out,
                            uint32_t *k_out, int *uses_bins)
{
    const uint32_t n = t->end - t->begin, leaf = b->leaf;
    const uint32_t kmax = leaf * ((n - 1) / leaf);
    const uint64_t leaves = ((uint64_t)n + leaf - 1) / leaf;
    uint32_t nb = n / leaf < RC__BINS ? n / leaf : RC__BINS, i, k; /* ~leaf_size items a bin */
    int axis, best_axis = -1, valid[3];
    float best_cost = INFINITY, last, ext_best = -1.0f;
    uint32_t best_left = 0;

    *uses_bins = 0;
    /* axis of largest centroid extent: the fallback, and the axis when only
     * one split position is possible */
    axis = 0;
    for (i = 0; i < 3; ++i) {
        float e = t->cmax[i] - t->cmin[i];
        if (e > ext_best) {
            ext_best = e;
            axis = (int)i;
        }
    }
    if (kmax == leaf) { /* one legal k: nothing to choose but the axis */
        *k_out = leaf;
        return axis;
    }
    if (nb < 2) nb = 2;
    last = (float)(nb - 1);
    for (i = 0; i < 3; ++i) {
        const float e = t->cmax[i] - t->cmin[i];
        scale[i] = e > 0.0f ? (float)nb * (1.0f - 1.0f / 65536.0f) / e : 0.0f;
        valid[i] = e > 0.0f && scale[i] < INFINITY && scale[i] > 0.0f;
        if (!valid[i]) scale[i] = 0.0f; /* binned anyway; never used */
    }
    if (valid[0] | valid[1] | valid[2]) {
        rc__bin *b0 = b->bins[0], *b1 = b->bins[1], *b2 = b->bins[2];
        const rc__build_item *it = b->items + t->begin;
        const float m0 = t->cmin[0], m1 = t->cmin[1], m2 = t->cmin[2];
        const float s0 = scale[0], s1 = scale[1], s2 = scale[2];
        uint32_t a, j;
        for (a = 0; a < 3; ++a) {
            for (j = 0; j < nb; ++j) {
                rc__bin *bin = &b->bins[a][j];
                bin->lo[0] = bin->lo[1] = bin->lo[2] = INFINITY;
                bin->hi[0] = bin->hi[1] = bin->hi[2] = -INFINITY;
                bin->count = 0;
            }
        }
        for (j = 0; j < n; ++j) {
            const rc__build_item *p = &it[j];
            rc__bin_add(&b0[rc__bin_of(p->lo[0] + p->hi[0], m0, s0, last)], p);
            rc__bin_add(&b1[rc__bin_of(p->lo[1] + p->hi[1], m1, s1, last)], p);
            rc__bin_add(&b2[rc__bin_of(p->lo[2] + p->hi[2], m2, s2, last)], p);
        }
        for (a = 0; a < 3; ++a) {
            const rc__bin *bins = b->bins[a];
            float rarea[RC__BINS];
            uint32_t rcount[RC__BINS];
            float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
            uint32_t cnt = 0;
            if (!valid[a]) continue;
            for (j = nb - 1; j > 0; --j) { /* right side of boundary j: bins j .. nb-1 */
                rc__box_grow(lo, hi, &bins[j]);
                cnt += bins[j].count;
                rarea[j] = rc__half_area(lo, hi);
                rcount[j] = cnt;
            }
            lo[0] = lo[1] = lo[2] = INFINITY;
            hi[0] = hi[1] = hi[2] = -INFINITY;
            cnt = 0;
            for (j = 1; j < nb; ++j) { /* left side: bins 0 .. j-1 */
                float cost;
                rc__box_grow(lo, hi, &bins[j - 1]);
                cnt += bins[j - 1].count;
                if (cnt == 0 || rcount[j] == 0) continue;
                cost = rc__half_area(lo, hi) * (float)((cnt + leaf - 1) / leaf) +
                       rarea[j] * (float)((rcount[j] + leaf - 1) / leaf);
                if (cost < best_cost) {
                    best_cost = cost;
                    best_axis = (int)a;
                    best_left = cnt;
                }
            }
        }
    }
    if (best_axis < 0) {
        /* all centroids coincide (or no usable axis): a balanced split */
        k = leaf * (uint32_t)(leaves / 2);
    } else {
        axis = best_axis;
        *uses_bins = 1;
        k = (best_left + leaf / 2) / leaf * leaf;
    }
    if (k < leaf) k = leaf;
    if (k > kmax) k = kmax;
    /* depth cap: both children must still fit a balanced subtree under it */
    {
        uint64_t ll = k / leaf, lr = leaves - ll, lm = ll > lr ? ll : lr;
        if (t->depth + 1 + rc__ceil_log2(lm) > RC__BVH_MAX_DEPTH) k = leaf * (uint32_t)(leaves / 2);
    }
    *nb_out = nb;
    *k_out = k;
    return axis;
}

/* Splits [begin, end) so that exactly k items go left; fills both children's
 * accumulators. */
static void rc__split(rc__builder *b, const rc__task *t, int axis, uint32_t k, int uses_bins,
                      float scale, uint32_t nb, rc__acc *left, rc__acc *right)
{
    rc__build_item *it = b->items + t->begin;
    const uint32_t n = t->end - t->begin;
    uint32_t i;
    rc__acc_reset(left);
    rc__acc_reset(right);
    if (uses_bins) {
        /* bin bs holds the k-th item: bins < bs all go left */
        const rc__bin *bins = b->bins[axis];
        uint32_t bs = 0, cum = 0, lo = 0, mid = 0, hi = n;
        const float cmin = t->cmin[axis], last = (float)(nb - 1);
        while (bs + 1 < nb && cum + bins[bs].count < k) cum += bins[bs++].count;
        /* three-way partition: [0, lo) < bs, [lo, hi) == bs, [hi, n) > bs */
        while (mid < hi) {
            const uint32_t bi = rc__bin_of(rc__centroid2(&it[mid], axis), cmin, scale, last);
            if (bi < bs) {
                rc__acc_add(left, &it[mid]);
                if (mid != lo) rc__swap(&it[mid], &it[lo]);
                ++lo;
                ++mid;
            } else if (bi > bs) {
                rc__acc_add(right, &it[mid]);
                --hi;
                if (mid != hi) rc__swap(&it[mid], &it[hi]);
            } else {
                ++mid;
            }
        }
        if (lo <= k && k <= hi) {
            const uint32_t need = k - lo;
            if (need > 0 && need < hi - lo) rc__select(it + lo, hi - lo, need, axis);
            for (i = lo; i < k; ++i) rc__acc_add(left, &it[i]);
            for (i = k; i < hi; ++i) rc__acc_add(right, &it[i]);
            return;
        }
        /* bins and partition disagree (cannot happen with identical float
         * operations): fall back to a full selection */
        rc__acc_reset(left);
        rc__acc_reset(right);
    }
    rc__select(it, n, k, axis);
    for (i = 0; i < k; ++i) rc__acc_add(left, &it[i]);
    for (i = k; i < n; ++i) rc__acc_add(right, &it[i]);
}

static void rc__task_init(rc__task *t, uint32_t node, uint32_t base, uint32_t begin, uint32_t end,
                          uint32_t depth, const rc__acc *a)
{
    int k;
    t->node = node;
    t->base = base;
    t->pad = 0;
    t->begin = begin;
    t->end = end;
    t->depth = depth;
    for (k = 0; k < 3; ++k) {
        t->cmin[k] = a->clo[k];
        t->cmax[k] = a->chi[k];
    }
}

/* Splits task t's node into its two children (boxes written, the node made
 * interior) and describes them in *l and *r. Node numbers depend only on leaf
 * counts: the children are the pair (base, base + 1), the left one's
 * descendants follow them, the right one's follow those. So every subtree
 * owns a range of nodes fixed before it is built, and subtrees can be built in
 * any order, on any thread, into the same array. */
static void rc__split_task(rc__builder *b, const rc__task *t, rc__task *l, rc__task *r)
{
    float scale[3] = {0.0f, 0.0f, 0.0f};
    uint32_t nb = 0, kleft = 0;
    int uses_bins, axis;
    rc__acc left, right;
    const uint32_t c = t->base;
    uint32_t ll;
    axis = rc__choose_split(b, t, scale, &nb, &kleft, &uses_bins);
    rc__split(b, t, axis, kleft, uses_bins, scale[axis], nb, &left, &right);
    ll = kleft / b->leaf; /* kleft is a multiple of the leaf size */
    b->nodes[t->node].index = c;
    b->nodes[t->node].count = 0;
    rc__set_node_box(&b->nodes[c], &left);
    rc__set_node_box(&b->nodes[c + 1], &right);
    rc__task_init(l, c, c + 2u, t->begin, t->begin + kleft, t->depth + 1, &left);
    rc__task_init(r, c + 1, c + 2u + 2u * ll - 2u, t->begin + kleft, t->end, t->depth + 1, &right);
}

/* Builds the subtree of task t (its node's box is set). */
static void rc__build_subtree(rc__builder *b, rc__task cur)
{
    rc__task stack[RC__STACK];
    uint32_t sp = 0;
    const uint32_t leaf_size = b->leaf;
    if (cur.end - cur.begin <= leaf_size) {
        rc__make_leaf(b, cur.node, cur.begin, cur.end);
        return;
    }
    for (;;) {
        rc__task tl, tr;
        int lleaf, rleaf;
        rc__split_task(b, &cur, &tl, &tr);
        lleaf = tl.end - tl.begin <= leaf_size;
        rleaf = tr.end - tr.begin <= leaf_size;
        if (lleaf) rc__make_leaf(b, tl.node, tl.begin, tl.end);
        if (rleaf) rc__make_leaf(b, tr.node, tr.begin, tr.end);
        if (!lleaf && !rleaf) {
            /* continue with the smaller: the stack stays O(log n) */
            if (tl.end - tl.begin <= tr.end - tr.begin) {
                stack[sp++] = tr;
                cur = tl;
            } else {
                stack[sp++] = tl;
                cur = tr;
            }
        } else if (!lleaf) {
            cur = tl;
        } else if (!rleaf) {
            cur = tr;
        } else if (sp > 0) {
            cur = stack[--sp];
        } else {
            return;
        }
    }
}

/* Subtrees handed to the pool: about this many per thread (they differ in
 * size, and the pool hands them out as threads free up), none smaller than
 * RC__PARALLEL_MIN_ITEMS (below that a thread's start-up is not worth it). */
#define RC__TASKS_PER_THREAD 8u
#define RC__PARALLEL_MIN_ITEMS 8192u
#define RC__MAX_PARALLEL_TASKS 256u

typedef struct rc__parallel_build {
    const rc__builder *proto;  /* shared arrays and leaf size */
    const rc__task *tasks;
    uint32_t first;            /* tasks of this round: first + task index */
} rc__parallel_build;

static void rc__subtree_task(void *user, uint32_t task, uint32_t thread)
{
    const rc__parallel_build *pb = (const rc__parallel_build *)user;
    rc__builder b = *pb->proto; /* own bins; progress is the caller's */
    (void)thread;
    b.progress = NULL;
    rc__build_subtree(&b, pb->tasks[pb->first + task]);
}

/* Largest task first; equal sizes by node number (deterministic). */
static int rc__task_before(const rc__task *a, const rc__task *b)
{
    const uint32_t na = a->end - a->begin, nb = b->end - b->begin;
    return na != nb ? na > nb : a->node < b->node;
}

/* Splits the largest subtrees on the calling thread until there are enough
 * for the pool, then builds them on the pool a round at a time, reporting
 * progress between rounds (progress is only ever called on the caller's
 * thread). The tree is the one the serial build makes, bit for bit: each
 * subtree's result depends only on its own items, and its node range is fixed
 * by the leaf counts (rc__split_task). */
static void rc__build_parallel(rc__builder *b, const rc__task *root, rc__pool *pool, uint32_t threads)
{
    rc__task tasks[RC__MAX_PARALLEL_TASKS];
    uint32_t count = 1, want = threads * RC__TASKS_PER_THREAD, i, j, done;
    rc__parallel_build pb;
    if (want > RC__MAX_PARALLEL_TASKS - 1u) want = RC__MAX_PARALLEL_TASKS - 1u;
    tasks[0] = *root;
    while (count < want) {
        rc__task t, l, r;
        /* tasks[0 .. count) stay sorted by rc__task_before */
        if (tasks[0].end - tasks[0].begin < RC__PARALLEL_MIN_ITEMS) break;
        t = tasks[0];
        for (i = 1; i < count; ++i) tasks[i - 1] = tasks[i];
        --count;
        rc__split_task(b, &t, &l, &r);
        for (j = 0; j < 2; ++j) {
            const rc__task *c = j ? &r : &l;
            if (c->end - c->begin <= b->leaf) {
                rc__make_leaf(b, c->node, c->begin, c->end);
                continue;
            }
            for (i = count; i > 0 && rc__task_before(c, &tasks[i - 1]); --i) tasks[i] = tasks[i - 1];
            tasks[i] = *c;
            ++count;
        }
        if (count == 0) return;
    }
    pb.proto = b;
    pb.tasks = tasks;
    for (done = 0; done < count;) {
        uint32_t n = count - done < 2u * threads ? count - done : 2u * threads;
        pb.first = done;
        rc__pool_run(pool, n, rc__subtree_task, &pb);
        for (i = done; i < done + n; ++i) b->placed += tasks[i].end - tasks[i].begin;
        done += n;
        if (b->progress && done < count) {
            b->progress(b->progress_user, "bvh build", (double)b->placed / (double)b->total);
            b->reported = b->placed;
        }
    }
}

void rc__bvh_build(const rc__aabb *item_bounds, uint32_t items, uint32_t leaf_size, void *scratch,
                   rc__bvh *out, rc_progress_fn progress, void *progress_user)
{
    rc__bvh_build_mt(item_bounds, items, leaf_size, scratch, out, NULL, progress, progress_user);
}

void rc__bvh_build_mt(const rc__aabb *item_bounds, uint32_t items, uint32_t leaf_size, void *scratch,
                      rc__bvh *out, rc__pool *pool, rc_progress_fn progress, void *progress_user)
{
    rc__builder b;
    rc__task root_task;
    rc__acc root;
    uint32_t i, threads = pool ? rc__pool_thread_count(pool) : 1u;

    if (leaf_size == 0) leaf_size = 1;
    out->item_count = items;
    out->leaf_size = leaf_size;
    out->node_count = rc__bvh_node_count(items, leaf_size);
    out->reserved0 = 0;
    if (items == 0) return;

    b.items = (rc__build_item *)scratch;
    b.nodes = out->nodes;
    b.leaf = leaf_size;
    b.placed = 0;
    b.total = items;
    b.report_step = items / 20 ? items / 20 : 1;
    b.next_report = b.report_step;
    b.reported = 0;
    b.progress = progress;
    b.progress_user = progress_user;

    rc__acc_reset(&root);
    for (i = 0; i < items; ++i) {
        rc__build_item *it = &b.items[i];
        const rc__aabb *ib = &item_bounds[i];
        int k;
        it->id = i;
        it->pad = 0;
        if (rc__box_empty(ib->min, ib->max)) {
            for (k = 0; k < 3; ++k) {
                it->lo[k] = INFINITY;
                it->hi[k] = -INFINITY;
            }
        } else {
            for (k = 0; k < 3; ++k) {
                it->lo[k] = ib->min[k];
                it->hi[k] = ib->max[k];
            }
        }
        rc__acc_add(&root, it);
    }
    if (progress) progress(progress_user, "bvh build", 0.0);

    rc__set_node_box(&b.nodes[0], &root);
    rc__task_init(&root_task, 0, 1, 0, items, 0, &root);
    if (threads > 1 && items >= 2u * RC__PARALLEL_MIN_ITEMS) {
        rc__build_parallel(&b, &root_task, pool, threads);
    } else {
        rc__build_subtree(&b, root_task);
    }
    for (i = 0; i < items; ++i) out->refs[i] = b.items[i].id;
    if (progress && b.reported != items) progress(progress_user, "bvh build", 1.0);
}

void rc__bvh_refit(rc__bvh *bvh, const rc__aabb *item_bounds)
{
    uint32_t i = bvh->node_count;
    while (i-- > 0) {
        rc__bvh_node *n = &bvh->nodes[i];
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        int k;
        if (n->count == 0) {
            const rc__bvh_node *a = &bvh->nodes[n->index], *c = &bvh->nodes[n->index + 1];
            for (k = 0; k < 3; ++k) {
                lo[k] = rc__fmin(a->bmin[k], c->bmin[k]);
                hi[k] = rc__fmax(a->bmax[k], c->bmax[k]);
            }
        } else {
            uint32_t j;
            for (j = n->index; j < n->index + n->count; ++j) {
                const rc__aabb *ib = &item_bounds[bvh->refs[j]];
                if (rc__box_empty(ib->min, ib->max)) continue;
                for (k = 0; k < 3; ++k) {
                    lo[k] = rc__fmin(ib->min[k], lo[k]);
                    hi[k] = rc__fmax(ib->max[k], hi[k]);
                }
            }
        }
        for (k = 0; k < 3; ++k) {
            n->bmin[k] = lo[k];
            n->bmax[k] = hi[k];
        }
    }
}
