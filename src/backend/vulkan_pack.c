/* Packing a committed scene into the flat arrays the kernels read (layout in
 * kernels/layout.glsl), and a C traversal of those arrays.
 *
 * The arrays are the canonical BVH, concatenated: every mesh's tree collapsed
 * into the CPU's 4-wide nodes (bvh/wide.h, rc__wide_collapse: one 128-byte
 * node takes four 32-byte node slots, 4-aligned, so it never straddles a
 * binding) and its refs as rc__bvh_build made them (child and leaf indices
 * stay relative to the mesh: the kernel adds node_base/ref_base), then the
 * scene's top level in binary nodes. A mesh updated in place keeps its
 * collapse's node count (a refit keeps the tree's shape), so its place. The
 * meshes are the scene's own geometries, then the geometries of every scene
 * its instances use, each such source once. Triangles are rewritten with
 * global vertex indices and vertices repacked to 3 floats whatever the input
 * stride; triangles are stored in leaf order (slot j of a mesh's refs holds
 * the vertex indices of triangle refs[j], so a leaf is one contiguous read and
 * the ref is read only for a hit's id), zero-area ones (rc__tri_zero_area) as
 * (a, a, a) so the kernel needs no double test for them. One builder, two traversals (this one and raycast.comp) of the same
 * arrays; the C one uses the CPU backend's own inner tests, so comparing it
 * with rc__scene_intersect checks the packing alone. */
#include "backend/vulkan_internal.h"

#include "bvh/intersect.h"

#include <math.h>
#include <string.h>

static void span_write(const rc__vk_span *s, uint64_t first, const void *src, uint64_t count)
{
    const unsigned char *p = (const unsigned char *)src;
    const uint64_t per = (uint64_t)1 << s->shift;
    first -= s->base;
    while (count) {
        const uint64_t c = first >> s->shift, off = first & (per - 1u);
        const uint64_t room = per - off, n = count < room ? count : room;
        memcpy(s->chunk[c] + off * s->elem_size, p, (size_t)(n * s->elem_size));
        p += n * s->elem_size;
        first += n;
        count -= n;
    }
}

/* Where element first of a span lies. */
static unsigned char *span_at(const rc__vk_span *s, uint64_t first)
{
    const uint64_t i = first - s->base;
    return s->chunk[i >> s->shift] + (i & (((uint64_t)1 << s->shift) - 1u)) * s->elem_size;
}

static rc__vk_scene *vk_scene_of(const rc_scene *scene) { return (rc__vk_scene *)scene->backend_scene; }

/* Every BVH starts at an odd node index, as in the scene's own block: its
 * sibling pairs (at odd indices within it) then fill whole 64-byte lines. */
static uint64_t pair_aligned(uint64_t node) { return node | 1u; }

/* Node slots one wide node takes, and a wide node's first slot at or after node. */
#define WIDE_SLOTS 4u
static uint64_t wide_aligned(uint64_t node) { return (node + WIDE_SLOTS - 1u) & ~(uint64_t)(WIDE_SLOTS - 1u); }

/* Wide nodes of geometry g's section in its own scene: its collapse's count,
 * which that scene's commit keeps (rc__vk_wide_counts), at least one (an
 * empty mesh's root). */
static uint64_t wide_of(const rc_scene *owner, uint32_t g)
{
    const uint32_t n = vk_scene_of(owner)->wide_nodes[g];
    return n ? n : 1u;
}

typedef struct pack_cursor {
    uint64_t node, ref, tri, vert, geom;
    uint64_t max_wide;
} pack_cursor;

/* Moves the cursor past m's sections (wide nodes), as fill_mesh does when it writes them. */
static void skip_mesh(const rc__mesh *m, uint64_t wide, pack_cursor *c)
{
    if (wide > c->max_wide) c->max_wide = wide;
    c->node = wide_aligned(c->node) + WIDE_SLOTS * wide;
    c->ref += m->bvh.item_count;
    c->tri += m->triangle_count;
    c->vert += m->vertex_count;
    c->geom += 1u;
}

rc_status rc__vk_wide_counts(rc__vk_state *st, rc_scene *scene, const uint8_t *changed, int *moved)
{
    rc__vk_scene *sv = vk_scene_of(scene);
    uint32_t g;
    int all = changed == NULL;
    *moved = 0;
    if (sv->wide_cap < scene->geom_count) {
        const uint32_t cap = scene->geom_count;
        uint32_t *n = (uint32_t *)rc__vk_host_alloc(st, (size_t)cap * sizeof *n);
        RC_RETURN_IF(st->ctx, n == NULL, RC_ERR_OUT_OF_MEMORY,
                     "rc_scene_commit: no host memory for the Vulkan node counts of %u meshes", (unsigned)cap);
        rc__vk_host_free(st, sv->wide_nodes);
        sv->wide_nodes = n;
        sv->wide_cap = cap;
        all = 1;
    }
    for (g = 0; g < scene->geom_count; ++g) {
        uint32_t n;
        if (!all && !changed[g]) continue;
        n = rc__wide_collapse(&scene->geoms[g].mesh.bvh, NULL);
        *moved |= n != sv->wide_nodes[g];
        sv->wide_nodes[g] = n;
    }
    *moved |= all;
    return RC_OK;
}

void rc__vk_pack_count(rc_scene *scene, uint32_t serial, rc__vk_pack_info *info)
{
    pack_cursor c;
    uint32_t g, i;
    memset(info, 0, sizeof *info);
    memset(&c, 0, sizeof c);
    for (g = 0; g < scene->geom_count; ++g) skip_mesh(&scene->geoms[g].mesh, wide_of(scene, g), &c);
    for (i = 0; i < scene->inst_count; ++i) {
        const rc_scene *src = scene->insts[i].source;
        rc__vk_scene *sv = vk_scene_of(src);
        if (sv->pack_serial == serial) continue;
        sv->pack_serial = serial;
        sv->pack_first_geom = (uint32_t)c.geom;
        for (g = 0; g < src->geom_count; ++g) skip_mesh(&src->geoms[g].mesh, wide_of(src, g), &c);
    }
    info->nodes = c.node;
    info->refs = c.ref;
    info->tris = c.tri;
    info->verts = c.vert;
    info->geoms = c.geom;
    info->insts = scene->inst_count;
    info->geom_count = scene->geom_count;
    info->max_wide = c.max_wide;
    info->top_node = (uint32_t)pair_aligned(info->nodes);
    info->top_ref = (uint32_t)info->refs;
    info->nodes = info->top_node;
    info->nodes += scene->top.node_count;
    info->refs += scene->top.item_count;
    info->flags = (scene->geom_count == 1 && scene->inst_count == 0) ? 1u : 0u;
}

#define PACK_BATCH 512u

static void fill_mesh(const rc__mesh *m, uint32_t geom_id, uint64_t wide, const rc__vk_pack_dst *dst,
                      pack_cursor *c)
{
    rc__vk_geom entry;
    rc__wnode *out;
    uint32_t batch[3u * PACK_BATCH];
    float vbatch[3u * PACK_BATCH];
    uint32_t i, k, n;
    while (c->node != wide_aligned(c->node)) { /* padding slots: never read */
        static const rc__bvh_node pad = {{0.0f, 0.0f, 0.0f}, 0u, {0.0f, 0.0f, 0.0f}, 0u};
        span_write(&dst->nodes, c->node, &pad, 1);
        c->node++;
    }
    entry.node_base = (uint32_t)c->node;
    entry.ref_base = (uint32_t)c->ref;
    entry.tri_base = (uint32_t)c->tri;
    entry.geom_id = geom_id;
    span_write(&dst->geoms, c->geom, &entry, 1);
    /* straight into place when the section cannot straddle two bindings
     * (no scratch given: the array is one binding), else through the scratch */
    out = dst->wide_scratch ? dst->wide_scratch : (rc__wnode *)(void *)span_at(&dst->nodes, c->node);
    if (rc__wide_collapse(&m->bvh, out) == 0) { /* no triangles: a root of empty slots */
        rc__wnode *w = out;
        for (i = 0; i < 4u; ++i) {
            for (k = 0; k < 3u; ++k) {
                w->box[2u * k][i] = INFINITY;
                w->box[2u * k + 1u][i] = -INFINITY;
            }
            w->child[i] = RC__WIDE_EMPTY;
            w->count[i] = 0;
        }
    }
    if (out == dst->wide_scratch) span_write(&dst->nodes, c->node, out, WIDE_SLOTS * wide);
    span_write(&dst->refs, c->ref, m->bvh.refs, m->bvh.item_count);
    for (i = 0; i < m->triangle_count; i += n) {
        n = m->triangle_count - i < PACK_BATCH ? m->triangle_count - i : PACK_BATCH;
        for (k = 0; k < n; ++k) {
            /* leaf order: slot i + k holds the triangle refs[i + k] names */
            const uint32_t *t = m->indices + (size_t)3u * m->bvh.refs[i + k];
            /* rc__tri_zero_area, decided once here in double: such a triangle
             * is written (a, a, a), which every test rejects (det == 0) */
            const int flat = rc__tri_zero_area(m->vertices + (size_t)t[0] * m->stride,
                                               m->vertices + (size_t)t[1] * m->stride,
                                               m->vertices + (size_t)t[2] * m->stride);
            batch[3u * k] = t[0] + (uint32_t)c->vert;
            batch[3u * k + 1u] = (flat ? t[0] : t[1]) + (uint32_t)c->vert;
            batch[3u * k + 2u] = (flat ? t[0] : t[2]) + (uint32_t)c->vert;
        }
        span_write(&dst->tris, c->tri + i, batch, n);
    }
    for (i = 0; i < m->vertex_count; i += n) {
        n = m->vertex_count - i < PACK_BATCH ? m->vertex_count - i : PACK_BATCH;
        for (k = 0; k < n; ++k) memcpy(vbatch + 3u * k, m->vertices + (size_t)(i + k) * m->stride, 3 * sizeof(float));
        span_write(&dst->verts, c->vert + i, vbatch, n);
    }
    skip_mesh(m, wide, c);
}

/* Instance i's record: its transforms and where its source's meshes are
 * (sources tagged by rc__vk_pack_count). */
static void instance_record(const rc__instance *in, rc__vk_inst *entry)
{
    const rc__vk_scene *sv = vk_scene_of(in->source);
    double d[12];
    int r;
    memset(entry, 0, sizeof *entry);
    for (r = 0; r < 3; ++r) {
        entry->to_local[4 * r + 0] = in->to_local.r[3 * r + 0];
        entry->to_local[4 * r + 1] = in->to_local.r[3 * r + 1];
        entry->to_local[4 * r + 2] = in->to_local.r[3 * r + 2];
        entry->to_local[4 * r + 3] = in->to_local.t[r];
        entry->n2w[4 * r + 0] = in->normal_to_world[3 * r + 0];
        entry->n2w[4 * r + 1] = in->normal_to_world[3 * r + 1];
        entry->n2w[4 * r + 2] = in->normal_to_world[3 * r + 2];
    }
    memcpy(d, in->to_world.rd, 9 * sizeof(double));
    memcpy(d + 9, in->to_world.td, 3 * sizeof(double));
    memcpy(entry->to_world_d, d, sizeof entry->to_world_d);
    entry->first_geom = sv->pack_first_geom;
    entry->geom_count = in->source->geom_count;
}

void rc__vk_pack_fill(rc_scene *scene, uint32_t serial, const rc__vk_pack_info *info, const rc__vk_pack_dst *dst)
{
    pack_cursor c;
    uint32_t g, i;
    memset(&c, 0, sizeof c);
    for (g = 0; g < scene->geom_count; ++g) fill_mesh(&scene->geoms[g].mesh, g, wide_of(scene, g), dst, &c);
    for (i = 0; i < scene->inst_count; ++i) {
        const rc__instance *in = &scene->insts[i];
        rc__vk_scene *sv = vk_scene_of(in->source);
        if (sv->fill_serial != serial) { /* first use of this source: its meshes go here */
            sv->fill_serial = serial;
            for (g = 0; g < in->source->geom_count; ++g)
                fill_mesh(&in->source->geoms[g].mesh, g, wide_of(in->source, g), dst, &c);
        }
    }
    if (c.node < info->top_node) {
        static const rc__bvh_node pad = {{0.0f, 0.0f, 0.0f}, 0u, {0.0f, 0.0f, 0.0f}, 0u};
        span_write(&dst->nodes, c.node, &pad, 1);
    }
    rc__vk_pack_fill_top(scene, info, dst);
}

/* Appends m's section at cursor c to out (while there is room) and moves c past it. */
static void note_section(const rc_scene *owner, uint32_t geom_id, int write, pack_cursor *c, rc__vk_section *out,
                         uint32_t max, uint32_t *n)
{
    const rc__mesh *m = &owner->geoms[geom_id].mesh;
    const uint64_t wide = wide_of(owner, geom_id);
    if (write && *n < max) {
        rc__vk_section *s = &out[*n];
        s->mesh = m;
        s->geom_id = geom_id;
        s->geom = c->geom;
        s->node = c->node;
        s->nodes = wide_aligned(c->node) + WIDE_SLOTS * wide - c->node;
        s->wide = wide;
        s->ref = c->ref;
        s->refs = m->bvh.item_count;
        s->tri = c->tri;
        s->tris = m->triangle_count;
        s->vert = c->vert;
        s->verts = m->vertex_count;
    }
    *n += write ? 1u : 0u;
    skip_mesh(m, wide, c);
}

uint32_t rc__vk_pack_changed(rc_scene *scene, uint32_t serial, const uint8_t *changed, rc__vk_section *out,
                             uint32_t max)
{
    pack_cursor c;
    uint32_t g, i, n = 0;
    memset(&c, 0, sizeof c);
    for (g = 0; g < scene->geom_count; ++g) note_section(scene, g, changed[g] != 0, &c, out, max, &n);
    for (i = 0; i < scene->inst_count; ++i) {
        const rc_scene *source = scene->insts[i].source;
        rc__vk_scene *sv = vk_scene_of(source);
        /* every instance of a source saw the same version at the last commit */
        const int moved = source->version != scene->source_versions[i];
        if (sv->fill_serial == serial) continue;
        sv->fill_serial = serial;
        for (g = 0; g < source->geom_count; ++g) note_section(source, g, moved, &c, out, max, &n);
    }
    return n;
}

void rc__vk_pack_section(const rc__vk_section *s, const rc__vk_pack_dst *dst)
{
    pack_cursor c;
    c.node = s->node;
    c.ref = s->ref;
    c.tri = s->tri;
    c.vert = s->vert;
    c.geom = s->geom;
    fill_mesh(s->mesh, s->geom_id, s->wide, dst, &c);
}

void rc__vk_pack_fill_top(const rc_scene *scene, const rc__vk_pack_info *info, const rc__vk_pack_dst *dst)
{
    uint32_t i;
    for (i = 0; i < scene->inst_count; ++i) {
        rc__vk_inst entry;
        instance_record(&scene->insts[i], &entry);
        span_write(&dst->insts, i, &entry, 1);
    }
    span_write(&dst->nodes, info->top_node, scene->top.nodes, scene->top.node_count);
    span_write(&dst->refs, info->top_ref, scene->top.refs, scene->top.item_count);
}

/* ---- the C traversal of the packed arrays -------------------------------------- */

/* One mesh of the packed arrays, walked by the CPU's own wide traversal
 * through a mesh that views them: its nodes where the section starts, its
 * leaf-order triangles (global vertex indices into the packed vertices) and
 * refs. */
static int packed_mesh(const rc__vk_packed *p, uint32_t gi, uint32_t geom_id, uint32_t inst, const rc__ray *ray,
                       rc__hit *hit)
{
    const rc__vk_geom g = p->geoms[gi];
    rc__mesh view;
    memset(&view, 0, sizeof view);
    view.vertices = p->verts;
    view.stride = 3;
    view.bvh.refs = (uint32_t *)(uintptr_t)(p->refs + g.ref_base); /* only read */
    view.leaf_tris = p->tris + (size_t)3u * g.tri_base;
    view.wide = (const rc__wnode *)(const void *)(p->nodes + g.node_base);
    view.wide_count = 1; /* any non-zero: the walk follows child indices */
    return rc__mesh_intersect_wide(&view, ray, geom_id, inst, hit);
}

int rc__vk_packed_intersect(const rc__vk_packed *p, const rc__ray *ray, rc__hit *hit)
{
    uint32_t stack[RC__BVH_MAX_DEPTH + 1];
    uint32_t sp = 0, ni = 0;
    int found = 0;
    rc__slab_ray s;
    if (p->info.flags & 1u) return packed_mesh(p, 0, 0, RC_INVALID_ID, ray, hit);
    rc__slab_ray_init(&s, ray);
    for (;;) {
        const rc__bvh_node *n = &p->nodes[p->info.top_node + ni];
        float tn;
        if (rc__node_hit(n, &s, hit->t, &tn)) {
            if (n->count == 0) {
                if (sp <= RC__BVH_MAX_DEPTH) stack[sp++] = n->index + 1;
                ni = n->index;
                continue;
            } else {
                uint32_t k;
                for (k = 0; k < n->count; ++k) {
                    const uint32_t item = p->refs[p->info.top_ref + n->index + k];
                    if (item < p->info.geom_count) {
                        found |= packed_mesh(p, item, item, RC_INVALID_ID, ray, hit);
                    } else {
                        const uint32_t inst = item - p->info.geom_count;
                        const rc__vk_inst *in = &p->insts[inst];
                        float r[9], o[3], d[3];
                        rc__ray local;
                        uint32_t g;
                        int a;
                        for (a = 0; a < 3; ++a) {
                            r[3 * a] = in->to_local[4 * a];
                            r[3 * a + 1] = in->to_local[4 * a + 1];
                            r[3 * a + 2] = in->to_local[4 * a + 2];
                        }
                        rc__rot_apply_f(r, ray->org, o);
                        o[0] += in->to_local[3];
                        o[1] += in->to_local[7];
                        o[2] += in->to_local[11];
                        rc__rot_apply_f(r, ray->dir, d);
                        rc__ray_prepare(&local, o, d);
                        for (g = 0; g < in->geom_count; ++g)
                            found |= packed_mesh(p, in->first_geom + g, g, inst, &local, hit);
                    }
                }
            }
        }
        if (sp == 0) break;
        ni = stack[--sp];
    }
    return found;
}
