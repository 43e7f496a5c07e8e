/* A firmware-style user of the static library, as small as it gets: one static
 * block for everything, no malloc, a two-triangle wall 5 m ahead, one ray.
 *
 * It uses only the public header and links librangecast.a with nothing but
 * libc and libm (and pthreads when the library has threads): tests/CMakeLists
 * builds it twice, dynamically (then checks its DT_NEEDED list) and with
 * -static, and runs both (under qemu-user in cross builds).
 *
 * malloc, calloc and realloc are wrapped (-Wl,--wrap=...) and counted from
 * before rc_context_create to after rc_context_destroy: the library must not
 * call them when the caller hands it a block. One thread (thread_count = 1),
 * as on a single-core board; pthread_create's own TLS allocation would
 * otherwise count in the -static build, where libc's internal calls are
 * wrapped too.
 *
 * Exits 0 when the range is 5 m, 1 with a message otherwise. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "rangecast/rangecast.h"

void *__real_malloc(size_t size);
void *__real_calloc(size_t n, size_t size);
void *__real_realloc(void *p, size_t size);
void *__wrap_malloc(size_t size);
void *__wrap_calloc(size_t n, size_t size);
void *__wrap_realloc(void *p, size_t size);

static int counting;
static unsigned allocations;

void *__wrap_malloc(size_t size)
{
    allocations += (unsigned)counting;
    return __real_malloc(size);
}
void *__wrap_calloc(size_t n, size_t size)
{
    allocations += (unsigned)counting;
    return __real_calloc(n, size);
}
void *__wrap_realloc(void *p, size_t size)
{
    allocations += (unsigned)counting;
    return __real_realloc(p, size);
}

/* The arena: a static array, aligned to RC_ARENA_ALIGNMENT by hand (C99 has
 * no alignas; firmware would use a linker-script section instead). */
#define BLOCK_BYTES (64u * 1024u)
static unsigned char block_storage[BLOCK_BYTES + RC_ARENA_ALIGNMENT];

/* A 2 x 2 m wall in the plane x = 5, facing the origin. */
static const float wall_vertices[4 * 3] = {
    5.0f, -1.0f, -1.0f,
    5.0f,  1.0f, -1.0f,
    5.0f,  1.0f,  1.0f,
    5.0f, -1.0f,  1.0f,
};
static const uint32_t wall_indices[2 * 3] = {0, 1, 2, 0, 2, 3};
static const float ray_direction[3] = {1.0f, 0.0f, 0.0f};

static int failed(const rc_context *ctx, const char *what, rc_status st)
{
    counting = 0;
    fprintf(stderr, "static_link: %s -> %s (%s)\n", what, rc_status_string(st), ctx ? rc_context_last_error(ctx) : "");
    return 1;
}

#define TRY(what, expr)                                   \
    do {                                                  \
        rc_status st_ = (expr);                           \
        if (st_ != RC_OK) return failed(ctx, what, st_);  \
    } while (0)

int main(void)
{
    unsigned char *block = block_storage + (RC_ARENA_ALIGNMENT - (size_t)((uintptr_t)block_storage % RC_ARENA_ALIGNMENT)) % RC_ARENA_ALIGNMENT;
    rc_context_desc cd = rc_context_desc_default();
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    rc_rays_desc rd = rc_rays_desc_default();
    rc_memory_stats ms = rc_memory_stats_default();
    rc_results res = rc_results_default();
    rc_context *ctx = NULL;
    rc_scene *scene = NULL;
    rc_sensor *sensor = NULL;
    rc_pose pose = rc_pose_identity();
    size_t need_ctx = 0, need_scene = 0, need_sensor = 0;
    uint32_t geom = 0, backend = 0;
    uint8_t hit = 0;
    float range = 0.0f;
    uint32_t prim = RC_INVALID_ID;

    cd.backend = RC_BACKEND_BVH;
    cd.thread_count = 1;
    cd.memory = block;
    cd.memory_size = BLOCK_BYTES;
    sd.max_geometries = 1;
    sd.max_triangles = 2;
    md.vertices = wall_vertices;
    md.vertex_count = 4;
    md.indices = wall_indices;
    md.triangle_count = 2;
    rd.common.range_min = 0.1f;
    rd.common.range_max = 100.0f;
    rd.directions = ray_direction;
    rd.ray_count = 1;

    counting = 1;
    TRY("rc_context_memory_requirements", rc_context_memory_requirements(&cd, &need_ctx));
    TRY("rc_sensor_memory_requirements_rays", rc_sensor_memory_requirements_rays(RC_SENSOR_O1DN, &rd, &need_sensor));
    TRY("rc_context_create", rc_context_create(&cd, &ctx));
    TRY("rc_scene_memory_requirements", rc_scene_memory_requirements(ctx, &sd, &need_scene));
    TRY("rc_context_get_backend", rc_context_get_backend(ctx, &backend));
    TRY("rc_sensor_create_rays", rc_sensor_create_rays(ctx, RC_SENSOR_O1DN, &rd, &sensor));
    TRY("rc_scene_create", rc_scene_create(ctx, &sd, &scene));
    TRY("rc_scene_add_mesh", rc_scene_add_mesh(scene, &md, &geom));
    TRY("rc_scene_commit", rc_scene_commit(scene));
    res.attributes = RC_ATTR_HITS | RC_ATTR_RANGES | RC_ATTR_PRIM_IDS;
    res.capacity = 1;
    res.hits = &hit;
    res.ranges = &range;
    res.prim_ids = &prim;
    TRY("rc_simulate", rc_simulate(ctx, scene, sensor, &pose, 1, &res));
    TRY("rc_context_get_memory_stats", rc_context_get_memory_stats(ctx, &ms));
    rc_context_destroy(ctx);
    counting = 0;

    printf("static_link: %s backend, range %.6f m, triangle %u, arena peak %lu of %lu bytes "
           "(requirements: context %lu + sensor %lu + scene %lu)\n",
           rc_backend_name(backend), (double)range, (unsigned)prim, (unsigned long)ms.arena_peak,
           (unsigned long)BLOCK_BYTES, (unsigned long)need_ctx, (unsigned long)need_sensor,
           (unsigned long)need_scene);
    if (allocations != 0) {
        fprintf(stderr, "static_link: %u malloc/calloc/realloc calls with a caller's block\n", allocations);
        return 1;
    }
    if (backend != RC_BACKEND_BVH || hit != 1 || fabsf(range - 5.0f) > 1e-5f || prim > 1) {
        fprintf(stderr, "static_link: wrong result: backend %u hit %u range %f prim %u\n", (unsigned)backend,
                (unsigned)hit, (double)range, (unsigned)prim);
        return 1;
    }
    if (ms.arena_peak > need_ctx + need_sensor + need_scene) {
        fprintf(stderr, "static_link: arena peak %lu exceeds the summed requirements %lu\n",
                (unsigned long)ms.arena_peak, (unsigned long)(need_ctx + need_sensor + need_scene));
        return 1;
    }
    return 0;
}
