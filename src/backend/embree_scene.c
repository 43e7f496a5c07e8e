/* Scenes as Embree scenes. Commit turns each mesh into an Embree triangle
 * geometry with the same id, sharing the mesh's own arrays, and each instance
 * into an Embree instance of its source's Embree scene (id max_geometries + i),
 * then commits.
 *
 * Sharing and Embree's padding rule: Embree reads each vertex with a 16-byte
 * load, so the 4 bytes after the last vertex must be readable. The index
 * buffer is always shared. The vertex buffer is shared when that holds:
 * - vertex_stride >= 16 bytes: the last vertex's 16 bytes lie inside its own
 *   stride (we take a strided array to hold vertex_count * stride bytes, as
 *   every strided layout does);
 * - RC_MESH_COPY meshes: their vertices sit in the scene block, followed by
 *   more copied vertices, padding or the copied-index table (checked);
 * and only the remaining case, a referenced mesh of packed xyz (stride 12),
 * is copied into a buffer Embree allocates padded (counted and budgeted like
 * the rest of Embree's memory: 12 bytes a vertex).
 *
 * The tie rule: the built-in backend reports, among hits at exactly the same
 * distance, the lowest (instance, geometry, triangle). Embree reports
 * whichever it meets last, and an intersection filter cannot fix it (Embree
 * stops at the first accepted hit within a leaf). Equal distances come from
 * identical triangles: a mesh holding the same triangle twice (overlapping
 * copies of a wall, say). Commit finds, per mesh, triangles whose three vertex
 * positions equal an earlier triangle's in the same order (the only duplicates
 * that are guaranteed the same distance bit for bit), and the tracer reports
 * the lowest of them. Across instances, twins (the same source at the same
 * transform, bit for bit: find_twin_instances) give the same hit, and the
 * lowest reports it. Rays through a shared edge, partly overlapping coplanar
 * triangles, and duplicates across meshes, in another vertex order or under
 * different transforms may still report a different (equally near) triangle
 * than the built-in backend. */
#include "backend/embree_impl.h"
#include "core/crc32c.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

static size_t align16(size_t n) { return (n + 15u) & ~(size_t)15u; }

/* Hash slots for finding twin instances: a power of two, at least twice the
 * instances (0 without instances). */
static size_t twin_slot_count(uint32_t max_insts)
{
    size_t n = 16;
    if (max_insts == 0) return 0;
    while (n < (size_t)max_insts * 2u) n <<= 1;
    return n;
}

static size_t block_size(const rc_scene_desc *desc)
{
    size_t geoms = desc->max_geometries ? desc->max_geometries : 1u;
    return align16(sizeof(rc__emb_scene)) + align16(geoms * sizeof(rc__emb_geom)) +
           align16((size_t)desc->max_instances * sizeof(RTCGeometry)) +
           align16((size_t)desc->max_instances * sizeof(uint32_t)) +
           twin_slot_count(desc->max_instances) * sizeof(uint32_t);
}

size_t rc__emb_scene_bytes(const rc_scene_desc *desc) { return rc__arena_cost(block_size(desc)); }

uint32_t rc__emb_canonical_prim(const rc__emb_geom *g, uint32_t prim)
{
    uint32_t lo = 0, hi = g->dup_count;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2u;
        uint32_t p = g->dups[2u * mid];
        if (p == prim) return g->dups[2u * mid + 1u];
        if (p < prim)
            lo = mid + 1u;
        else
            hi = mid;
    }
    return prim;
}

static void free_dups(rc__emb_device *d, rc__emb_geom *g)
{
    if (g->dups) {
        free(g->dups);
        (void)rc__emb_account(d, -(int64_t)((size_t)g->dup_count * 2u * sizeof(uint32_t)), "");
    }
    g->dups = NULL;
    g->dup_count = 0;
    g->dups_done = 0;
}

/* The three vertices of a triangle, -0 read as +0 so equal positions hash
 * equal. */
static void tri_positions(const rc__mesh *m, uint32_t prim, float p[9])
{
    const uint32_t *tri = m->indices + (size_t)3u * prim;
    int k, j;
    for (k = 0; k < 3; ++k)
        for (j = 0; j < 3; ++j) p[3 * k + j] = m->vertices[(size_t)tri[k] * m->stride + (size_t)j] + 0.0f;
}

static uint64_t hash_positions(const float p[9])
{
    uint64_t h = 0x9E3779B97F4A7C15ull;
    int i;
    for (i = 0; i < 9; ++i) {
        uint32_t bits;
        memcpy(&bits, &p[i], sizeof bits);
        h ^= bits;
        h *= 0xFF51AFD7ED558CCDull;
        h ^= h >> 32;
    }
    return h;
}

static int same_positions(const float a[9], const float b[9])
{
    int i;
    for (i = 0; i < 9; ++i)
        if (a[i] != b[i]) return 0;
    return 1;
}

/* Fills g->dups for mesh m: an open-addressing table of first occurrences,
 * probed in ascending triangle order, so each duplicate maps to the lowest
 * identical triangle. A slot holds the triangle and 32 more bits of its hash,
 * so probes compare vertices only on a likely match. Temporary table: 16 bytes
 * a triangle. */
static rc_status find_duplicates(rc__emb_device *d, const rc__mesh *m, rc__emb_geom *g)
{
    const uint64_t empty = ~(uint64_t)0;
    size_t slots = 16, mask, table_bytes;
    uint64_t *table;
    uint32_t *pairs = NULL;
    uint32_t count = 0, cap = 0, prim;
    rc_status st = RC_OK;

    free_dups(d, g);
    if (m->triangle_count < 2) {
        g->dups_done = 1;
        return RC_OK;
    }
    while (slots < (size_t)m->triangle_count * 2u) slots <<= 1;
    mask = slots - 1u;
    table_bytes = slots * sizeof(uint64_t);
    RC_TRY(rc__emb_account(d, (int64_t)table_bytes, "rc_scene_commit (duplicate-triangle table)"));
    table = (uint64_t *)malloc(table_bytes);
    if (!table) {
        (void)rc__emb_account(d, -(int64_t)table_bytes, "");
        return rc__fail(d->ctx, RC_ERR_OUT_OF_MEMORY, "rc_scene_commit: malloc of %llu bytes failed",
                        (unsigned long long)table_bytes);
    }
    memset(table, 0xFF, table_bytes);
    for (prim = 0; prim < m->triangle_count && st == RC_OK; ++prim) {
        float p[9], q[9];
        uint64_t h;
        uint32_t tag;
        size_t s;
        tri_positions(m, prim, p);
        h = hash_positions(p);
        tag = (uint32_t)(h >> 32);
        for (s = (size_t)h & mask;; s = (s + 1u) & mask) {
            uint32_t other;
            if (table[s] == empty) {
                table[s] = (uint64_t)tag << 32 | prim;
                break;
            }
            if ((uint32_t)(table[s] >> 32) != tag) continue;
            other = (uint32_t)table[s];
            tri_positions(m, other, q);
            if (!same_positions(p, q)) continue;
            if (count == cap) {
                uint32_t ncap = cap ? cap * 2u : 64u;
                uint32_t *np;
                st = rc__emb_account(d, (int64_t)((size_t)(ncap - cap) * 2u * sizeof(uint32_t)),
                                     "rc_scene_commit (duplicate-triangle list)");
                if (st != RC_OK) break;
                np = (uint32_t *)realloc(pairs, (size_t)ncap * 2u * sizeof(uint32_t));
                if (!np) {
                    (void)rc__emb_account(d, -(int64_t)((size_t)(ncap - cap) * 2u * sizeof(uint32_t)), "");
                    st = rc__fail(d->ctx, RC_ERR_OUT_OF_MEMORY,
                                  "rc_scene_commit: realloc of the duplicate list failed");
                    break;
                }
                pairs = np;
                cap = ncap;
            }
            pairs[2u * count] = prim;
            pairs[2u * count + 1u] = other;
            ++count;
            break;
        }
    }
    free(table);
    (void)rc__emb_account(d, -(int64_t)table_bytes, "");
    if (st != RC_OK) {
        free(pairs);
        (void)rc__emb_account(d, -(int64_t)((size_t)cap * 2u * sizeof(uint32_t)), "");
        return st;
    }
    if (count == 0) {
        free(pairs);
        (void)rc__emb_account(d, -(int64_t)((size_t)cap * 2u * sizeof(uint32_t)), "");
        pairs = NULL;
    } else if (count < cap) {
        /* keep exactly what is used */
        uint32_t *np = (uint32_t *)realloc(pairs, (size_t)count * 2u * sizeof(uint32_t));
        if (np) pairs = np;
        (void)rc__emb_account(d, -(int64_t)((size_t)(cap - count) * 2u * sizeof(uint32_t)), "");
    }
    g->dups = pairs;
    g->dup_count = count;
    g->dups_done = 1;
    return RC_OK;
}

/* 1 when Embree may read 16 bytes at the last vertex of geometry gi in place. */
static int vertices_shareable(const rc_scene *scene, uint32_t gi)
{
    const rc__geometry *geo = &scene->geoms[gi];
    const rc__mesh *m = &geo->mesh;
    if (m->stride >= 4u) return 1;
    if (geo->flags == RC_MESH_COPY && scene->copy_vertices && scene->copy_indices) {
        const float *last = m->vertices + (size_t)(m->vertex_count - 1u) * 3u;
        const unsigned char *last_end = (const unsigned char *)last + 16u;
        const unsigned char *lo = (const unsigned char *)scene->copy_vertices;
        const unsigned char *hi =
            (const unsigned char *)(scene->copy_indices + (size_t)scene->desc.max_copied_triangles * 3u);
        return (const unsigned char *)m->vertices >= lo && last_end <= hi &&
               (const unsigned char *)scene->copy_indices > (const unsigned char *)m->vertices;
    }
    return 0;
}

static void copy_vertices(const rc__mesh *m, float *dst)
{
    uint32_t i;
    for (i = 0; i < m->vertex_count; ++i) memcpy(dst + (size_t)i * 3u, m->vertices + (size_t)i * m->stride, 12u);
}

/* Embree's build quality for a scene's rc_scene_desc.build_quality (COMPACT
 * builds as BALANCED; its flag is in scene_flags). */
static enum RTCBuildQuality quality_of(const rc_scene *scene)
{
    switch (scene->desc.build_quality) {
    case RC_BUILD_FAST: return RTC_BUILD_QUALITY_LOW;
    case RC_BUILD_HIGH: return RTC_BUILD_QUALITY_HIGH;
    default: return RTC_BUILD_QUALITY_MEDIUM;
    }
}

static enum RTCSceneFlags scene_flags(const rc__emb_device *d, const rc_scene *scene)
{
    int flags = d->options.robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE;
    if (scene->desc.build_quality == RC_BUILD_COMPACT) flags |= RTC_SCENE_FLAG_COMPACT;
    return (enum RTCSceneFlags)flags;
}

/* Flags and build quality of the Embree scene that holds the meshes. Once a
 * mesh has been updated (es->dynamic) it builds in two levels: a tree per
 * mesh, kept across commits, and a small tree over the meshes. Embree takes
 * its two-level builder for RTC_BUILD_QUALITY_LOW scenes; each mesh's own
 * tree still builds with the geometry's quality (quality_of), and an updated
 * mesh's is refitted (geometry_update). Otherwise one tree over all the
 * meshes' triangles traces faster, but updating any mesh rebuilds it whole. */
static void mesh_scene_settings(const rc__emb_device *d, const rc__emb_scene *es, const rc_scene *scene,
                                RTCScene s)
{
    int flags = (int)scene_flags(d, scene);
    if (es->dynamic) flags |= RTC_SCENE_FLAG_DYNAMIC;
    rtcSetSceneFlags(s, (enum RTCSceneFlags)flags);
    rtcSetSceneBuildQuality(s, es->dynamic ? RTC_BUILD_QUALITY_LOW : quality_of(scene));
}

static rc_status geometry_create(rc__emb_device *d, rc__emb_scene *es, const rc_scene *scene, uint32_t gi)
{
    const rc__mesh *m = &scene->geoms[gi].mesh;
    rc__emb_geom *g = &es->geoms[gi];
    RTCGeometry geom = rtcNewGeometry(d->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rc_status st;
    if (!geom) {
        st = rc__emb_check(d, "rc_scene_commit (rtcNewGeometry)");
        return st != RC_OK ? st : rc__fail(d->ctx, RC_ERR_BACKEND, "rc_scene_commit: Embree: rtcNewGeometry failed");
    }
    if (vertices_shareable(scene, gi)) {
        rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, m->vertices, 0,
                                   (size_t)m->stride * sizeof(float), m->vertex_count);
        g->copied = 0;
    } else {
        float *v = (float *)rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                    3u * sizeof(float), m->vertex_count);
        if (v) copy_vertices(m, v);
        g->copied = 1;
    }
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, m->indices, 0,
                               3u * sizeof(uint32_t), m->triangle_count);
    rtcSetGeometryBuildQuality(geom, quality_of(scene));
    rtcCommitGeometry(geom);
    st = rc__emb_check(d, "rc_scene_commit (mesh geometry)");
    if (st == RC_OK) {
        rtcAttachGeometryByID(rc__emb_mesh_scene(es), geom, gi);
        st = rc__emb_check(d, "rc_scene_commit (rtcAttachGeometryByID)");
    }
    if (st != RC_OK) {
        /* not attached: the next commit starts this mesh afresh */
        rtcReleaseGeometry(geom);
        rc__emb_clear(d);
        return st;
    }
    g->geom = geom; /* our reference; the scene holds its own */
    return RC_OK;
}

/* The mesh's vertices changed in place (rc_scene_update_mesh). */
static rc_status geometry_update(rc__emb_device *d, const rc_scene *scene, rc__emb_geom *g, uint32_t gi)
{
    if (g->copied) {
        float *v = (float *)rtcGetGeometryBufferData(g->geom, RTC_BUFFER_TYPE_VERTEX, 0);
        if (v) copy_vertices(&scene->geoms[gi].mesh, v);
    }
    rtcUpdateGeometryBuffer(g->geom, RTC_BUFFER_TYPE_VERTEX, 0);
    /* same triangles, moved vertices: refit this mesh's tree (two-level
     * scenes, mesh_scene_settings) */
    rtcSetGeometryBuildQuality(g->geom, RTC_BUILD_QUALITY_REFIT);
    rtcCommitGeometry(g->geom);
    g->dups_done = 0;
    return rc__emb_check(d, "rc_scene_commit (mesh update)");
}

/* An instance geometry of child attached to parent by id (the caller sets
 * its transform and commits it). */
static rc_status new_instance(rc__emb_device *d, RTCScene parent, RTCScene child, uint32_t id, const char *what,
                              RTCGeometry *out)
{
    RTCGeometry geom = rtcNewGeometry(d->device, RTC_GEOMETRY_TYPE_INSTANCE);
    rc_status st;
    if (!geom) {
        st = rc__emb_check(d, "rc_scene_commit (rtcNewGeometry instance)");
        return st != RC_OK ? st : rc__fail(d->ctx, RC_ERR_BACKEND, "rc_scene_commit: Embree: rtcNewGeometry failed");
    }
    rtcSetGeometryInstancedScene(geom, child);
    rtcAttachGeometryByID(parent, geom, id);
    st = rc__emb_check(d, what);
    if (st != RC_OK) {
        rtcReleaseGeometry(geom);
        rc__emb_clear(d);
        return st;
    }
    *out = geom;
    return RC_OK;
}

static rc_status instance_set(rc__emb_device *d, rc__emb_scene *es, const rc_scene *scene, uint32_t i)
{
    const rc__instance *in = &scene->insts[i];
    const rc__emb_scene *src = (const rc__emb_scene *)in->source->backend_scene;
    float m[12];
    int r;
    RC_RETURN_IF(d->ctx, src == NULL, RC_ERR_NOT_COMMITTED, "the source scene of instance %u is not committed",
                 (unsigned)i);
    if (!es->insts[i])
        RC_TRY(new_instance(d, es->scene, rc__emb_mesh_scene(src), es->max_geoms + i,
                            "rc_scene_commit (instance geometry)", &es->insts[i]));
    for (r = 0; r < 3; ++r) {
        m[4 * r] = in->to_world.r[3 * r];
        m[4 * r + 1] = in->to_world.r[3 * r + 1];
        m[4 * r + 2] = in->to_world.r[3 * r + 2];
        m[4 * r + 3] = in->to_world.t[r];
    }
    rtcSetGeometryTransform(es->insts[i], 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, m);
    rtcCommitGeometry(es->insts[i]);
    return rc__emb_check(d, "rc_scene_commit (instance)");
}

/* es->inst_twin for the scene's instances (see embree_impl.h): an
 * open-addressing table of first occurrences, filled in instance order, so
 * each instance meets its lowest twin first. */
static void find_twin_instances(rc__emb_scene *es, const rc_scene *scene)
{
    uint32_t i;
    es->twins_any = 0;
    if (scene->inst_count < 2) {
        for (i = 0; i < scene->inst_count; ++i) es->inst_twin[i] = i;
        return;
    }
    memset(es->twin_slots, 0xFF, ((size_t)es->twin_mask + 1u) * sizeof(uint32_t));
    for (i = 0; i < scene->inst_count; ++i) {
        const rc__instance *in = &scene->insts[i];
        const uint32_t h = rc__crc32c(rc__crc32c(0, &in->source, sizeof in->source), &in->to_world,
                                      sizeof in->to_world);
        size_t s;
        for (s = (size_t)h & es->twin_mask;; s = (s + 1u) & es->twin_mask) {
            const uint32_t j = es->twin_slots[s];
            if (j == 0xFFFFFFFFu) {
                es->twin_slots[s] = i;
                es->inst_twin[i] = i;
                break;
            }
            if (scene->insts[j].source == in->source &&
                memcmp(&scene->insts[j].to_world, &in->to_world, sizeof in->to_world) == 0) {
                es->inst_twin[i] = j;
                es->twins_any = 1;
                break;
            }
        }
    }
}

static rc_status scene_state(rc__emb_device *d, rc_scene *scene, rc__emb_scene **out)
{
    rc_context *ctx = scene->ctx;
    size_t bytes = block_size(&scene->desc);
    unsigned char *block;
    rc__emb_scene *es = (rc__emb_scene *)scene->backend_scene;
    if (es) {
        *out = es;
        return RC_OK;
    }
    block = (unsigned char *)rc__arena_calloc(&ctx->arena, bytes);
    RC_RETURN_IF(ctx, block == NULL, RC_ERR_OUT_OF_MEMORY,
                 "arena has no room for the Embree scene tables (%llu bytes; largest free block %llu)",
                 (unsigned long long)rc__arena_cost(bytes), (unsigned long long)rc__arena_largest_free(&ctx->arena));
    es = (rc__emb_scene *)(void *)block;
    es->max_geoms = scene->desc.max_geometries ? scene->desc.max_geometries : 1u;
    es->max_insts = scene->desc.max_instances;
    es->geoms = (rc__emb_geom *)(void *)(block + align16(sizeof *es));
    if (es->max_insts) {
        unsigned char *p = block + align16(sizeof *es) + align16(es->max_geoms * sizeof(rc__emb_geom));
        es->insts = (RTCGeometry *)(void *)p;
        p += align16(es->max_insts * sizeof(RTCGeometry));
        es->inst_twin = (uint32_t *)(void *)p;
        es->twin_slots = (uint32_t *)(void *)(p + align16(es->max_insts * sizeof(uint32_t)));
        es->twin_mask = (uint32_t)(twin_slot_count(es->max_insts) - 1u);
    }
    es->mesh_inst_id = es->max_geoms + es->max_insts;
    es->scene = rtcNewScene(d->device);
    /* a scene that can hold instances keeps its meshes apart (see embree_impl.h) */
    if (es->scene && es->max_insts > 0) es->mesh_scene = rtcNewScene(d->device);
    if (!es->scene || (es->max_insts > 0 && !es->mesh_scene)) {
        rc_status st = rc__emb_check(d, "rc_scene_commit (rtcNewScene)");
        if (es->scene) rtcReleaseScene(es->scene);
        rc__arena_free(&ctx->arena, block);
        return st != RC_OK ? st : rc__fail(ctx, RC_ERR_BACKEND, "rc_scene_commit: Embree: rtcNewScene failed");
    }
    scene->backend_scene = es;
    *out = es;
    return RC_OK;
}

/* Embree's build progress, forwarded to the caller's callback. Embree may
 * report from several build threads at once; the caller's callback is called
 * by one at a time (the others skip their report). */
typedef struct progress_relay {
    rc_progress_fn fn;
    void *user;
    int busy;
} progress_relay;

#if defined(__GNUC__) || defined(__clang__)
static bool on_progress(void *ptr, double fraction)
{
    progress_relay *r = (progress_relay *)ptr;
    if (!__atomic_exchange_n(&r->busy, 1, __ATOMIC_ACQUIRE)) {
        r->fn(r->user, "embree build", fraction);
        __atomic_store_n(&r->busy, 0, __ATOMIC_RELEASE);
    }
    return true; /* the public callback cannot cancel (yet) */
}
#define RC__EMB_PROGRESS 1
#endif

/* rtcCommitScene, reporting Embree's build progress to progress (may be NULL). */
static void commit_scene(RTCScene s, rc_progress_fn progress, void *user)
{
#if defined(RC__EMB_PROGRESS)
    progress_relay relay;
    relay.fn = progress;
    relay.user = user;
    relay.busy = 0;
    if (progress) rtcSetSceneProgressMonitorFunction(s, on_progress, &relay);
    rtcCommitScene(s);
    if (progress) rtcSetSceneProgressMonitorFunction(s, NULL, NULL);
#else
    (void)progress;
    (void)user;
    rtcCommitScene(s);
#endif
}

/* The identity instance that places a split scene's meshes in its top scene
 * (created once; committed again when the meshes changed, so the top scene
 * sees their new bounds). */
static rc_status mesh_instance_set(rc__emb_device *d, rc__emb_scene *es, int meshes_changed)
{
    static const float identity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    if (!es->mesh_inst) {
        RC_TRY(new_instance(d, es->scene, es->mesh_scene, es->mesh_inst_id, "rc_scene_commit (mesh instance)",
                            &es->mesh_inst));
        rtcSetGeometryTransform(es->mesh_inst, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, identity);
        rtcCommitGeometry(es->mesh_inst);
    } else if (meshes_changed) {
        rtcCommitGeometry(es->mesh_inst);
    }
    return rc__emb_check(d, "rc_scene_commit (mesh instance)");
}

/* Bytes of the meshes' own index and vertex arrays (what the refinement
 * reads beside Embree's structures). */
uint64_t rc__emb_mesh_array_bytes(const rc_scene *scene)
{
    uint64_t bytes = 0;
    uint32_t g;
    for (g = 0; g < scene->geom_count; ++g) {
        const rc__mesh *m = &scene->geoms[g].mesh;
        bytes += (uint64_t)m->triangle_count * 3u * sizeof(uint32_t) + (uint64_t)m->vertex_count * m->stride * sizeof(float);
    }
    return bytes;
}

/* The occupancy grid of a scene whose own meshes are large enough for
 * ordered runs: made at its first such commit, made again when the triangle
 * count changes, or the bounds where the scene has no instances. A mesh moved
 * within the bounds leaves it stale, which only costs order (so a commit
 * after updating a small mesh stays cheap); so do instances (the grid does
 * not see them), whose moves would otherwise make every commit of a dynamic
 * map walk the whole map again. No grid where the budget has no room for it:
 * the calls then run scan by scan. */
static void update_occupancy(rc__emb_device *d, rc__emb_scene *es, const rc_scene *scene)
{
    rc__occupancy *g = es->occupancy;
    const uint64_t budget = d->options.budget_bytes;
    if (scene->geom_count == 0 || d->options.bytes_now + rc__emb_mesh_array_bytes(scene) <= scene->ctx->large_mesh_bytes)
        return;
    if (!g) {
        if (budget != 0 && d->options.bytes_now + sizeof *g > budget) return;
        g = (rc__occupancy *)malloc(sizeof *g);
        if (!g || rc__emb_account(d, (int64_t)sizeof *g, "rc_scene_commit (occupancy grid)") != RC_OK) {
            free(g);
            return;
        }
        es->occupancy = g;
    } else if (g->triangles == scene->triangle_count &&
               (scene->inst_count != 0 || memcmp(g->bounds, &scene->bounds, sizeof g->bounds) == 0)) {
        return;
    }
    rc__occupancy_build(g, scene);
}

rc_status rc__emb_scene_commit(rc_scene *scene, rc_progress_fn progress, void *user)
{
    rc__emb_device *d = (rc__emb_device *)scene->ctx->backend_data;
    rc__emb_scene *es = NULL;
    struct RTCBounds b;
    uint32_t i;
    int meshes_changed = 0;

    /* Every Embree call sequence is checked where it happens; what is pending
     * here came through the error callback between calls. */
    RC_TRY(rc__emb_check(d, "rc_scene_commit (pending)"));
    RC_TRY(scene_state(d, scene, &es));
    for (i = 0; i < scene->geom_count; ++i) es->dynamic |= es->geoms[i].geom != NULL && scene->geoms[i].dirty == 2;
    if (es->unfinished) {
        /* Embree 3.13's two-level build, stopped part way (a refused
         * allocation), keeps the meshes it had not finished as if built and
         * crashes on them next time: every mesh builds afresh */
        for (i = 0; i < scene->geom_count; ++i)
            if (es->geoms[i].geom) {
                rtcDetachGeometry(rc__emb_mesh_scene(es), i);
                rtcAttachGeometryByID(rc__emb_mesh_scene(es), es->geoms[i].geom, i);
            }
    }
    es->unfinished = 1;
    if (es->mesh_scene) {
        rtcSetSceneFlags(es->scene, scene_flags(d, scene));
        rtcSetSceneBuildQuality(es->scene, quality_of(scene));
    }
    mesh_scene_settings(d, es, scene, rc__emb_mesh_scene(es));
    for (i = 0; i < scene->geom_count; ++i) {
        rc__geometry *geo = &scene->geoms[i];
        rc__emb_geom *g = &es->geoms[i];
        if (!g->geom) {
            RC_TRY(geometry_create(d, es, scene, i));
            meshes_changed = 1;
        } else if (geo->dirty) {
            RC_TRY(geometry_update(d, scene, g, i));
            meshes_changed = 1;
        }
        if (!d->options.tie_rule)
            free_dups(d, g);
        else if (!g->dups_done)
            RC_TRY(find_duplicates(d, &geo->mesh, g));
    }
    if (progress) progress(user, "embree build", 0.0);
    if (es->mesh_scene && scene->geom_count > 0) {
        /* the map's own tree: rebuilt only when one of its meshes changed */
        if (meshes_changed || !es->mesh_inst) commit_scene(es->mesh_scene, progress, user);
        RC_TRY(rc__emb_check(d, "rc_scene_commit (meshes)"));
        RC_TRY(mesh_instance_set(d, es, meshes_changed));
    }
    for (i = 0; i < scene->inst_count; ++i) RC_TRY(instance_set(d, es, scene, i));
    if (d->options.tie_rule && scene->inst_count > 0)
        find_twin_instances(es, scene);
    else
        es->twins_any = 0;
    commit_scene(es->scene, es->mesh_scene ? NULL : progress, user);
    RC_TRY(rc__emb_check(d, "rc_scene_commit"));
    rtcGetSceneBounds(es->scene, &b);
    scene->bounds.min[0] = b.lower_x;
    scene->bounds.min[1] = b.lower_y;
    scene->bounds.min[2] = b.lower_z;
    scene->bounds.max[0] = b.upper_x;
    scene->bounds.max[1] = b.upper_y;
    scene->bounds.max[2] = b.upper_z;
    update_occupancy(d, es, scene);
    for (i = 0; i < scene->geom_count; ++i) scene->geoms[i].dirty = 0;
    scene->top_dirty = 0;
    es->unfinished = 0;
    if (progress) progress(user, "commit", 1.0);
    return RC_OK;
}

void rc__emb_scene_release(rc_scene *scene)
{
    rc__emb_device *d = (rc__emb_device *)scene->ctx->backend_data;
    rc__emb_scene *es = (rc__emb_scene *)scene->backend_scene;
    uint32_t i;
    if (!es) return;
    for (i = 0; i < es->max_insts; ++i)
        if (es->insts[i]) rtcReleaseGeometry(es->insts[i]);
    if (es->mesh_inst) rtcReleaseGeometry(es->mesh_inst);
    if (es->mesh_scene) rtcReleaseScene(es->mesh_scene);
    for (i = 0; i < es->max_geoms; ++i) {
        if (es->geoms[i].geom) rtcReleaseGeometry(es->geoms[i].geom);
        free_dups(d, &es->geoms[i]);
    }
    rtcReleaseScene(es->scene);
    if (es->occupancy) {
        free(es->occupancy);
        (void)rc__emb_account(d, -(int64_t)sizeof *es->occupancy, "");
    }
    rc__emb_clear(d);
    rc__arena_free(&scene->ctx->arena, es);
    scene->backend_scene = NULL;
}
