/* The core path makes no allocation after rc_context_create: malloc, calloc
 * and realloc are wrapped (-Wl,--wrap) and counted while a scene is built,
 * committed, a sensor made and a batch simulated on two threads, and while
 * the scene is baked into a block the caller made and loaded from it. */
#include <stdlib.h>

#include "rc_test.h"

void *__real_malloc(size_t size);
void *__real_calloc(size_t n, size_t size);
void *__real_realloc(void *p, size_t size);
void *__wrap_malloc(size_t size);
void *__wrap_calloc(size_t n, size_t size);
void *__wrap_realloc(void *p, size_t size);

static int counting;
static unsigned calls;

void *__wrap_malloc(size_t size)
{
    if (counting) calls++;
    return __real_malloc(size);
}
void *__wrap_calloc(size_t n, size_t size)
{
    if (counting) calls++;
    return __real_calloc(n, size);
}
void *__wrap_realloc(void *p, size_t size)
{
    if (counting) calls++;
    return __real_realloc(p, size);
}

static void test_no_allocation_after_create(void **state)
{
    rcu_mesh m;
    rc_context *ctx;
    rc_scene *scene, *top, *baked = NULL;
    void *blob;
    size_t blob_bytes = 0;
    rc_scene_desc sd = rc_scene_desc_default();
    rc_mesh_desc md = rc_mesh_desc_default();
    rc_instance_desc id = rc_instance_desc_default();
    rc_sensor *sensor;
    rct_buffers buf;
    rc_pose poses[4];
    uint32_t g, i;
    (void)state;
    assert_int_equal(rcu_mesh_uv_sphere(20.0f, 64, 32, &m), 0);
    rct_buffers_alloc(&buf, 4 * 16 * 900, RC_ATTR_ALL);
    for (i = 0; i < 4; ++i) poses[i] = rct_pose(0.5f * i, 0, 0);
    ctx = rct_context(RC_BACKEND_BVH, 2, 32);

    counting = 1;
    sd.max_triangles = m.triangle_count;
    sd.max_vertices = m.vertex_count;
    sd.max_copied_triangles = m.triangle_count;
    RCT_OK(ctx, rc_scene_create(ctx, &sd, &scene));
    md.flags = RC_MESH_COPY;
    md.vertices = m.vertices;
    md.vertex_count = m.vertex_count;
    md.indices = m.indices;
    md.triangle_count = m.triangle_count;
    RCT_OK(ctx, rc_scene_add_mesh(scene, &md, &g));
    RCT_OK(ctx, rc_scene_commit(scene));
    sd = rc_scene_desc_default();
    sd.max_instances = 2;
    RCT_OK(ctx, rc_scene_create(ctx, &sd, &top));
    id.source = scene;
    RCT_OK(ctx, rc_scene_add_instance(top, &id, &g));
    RCT_OK(ctx, rc_scene_commit(top));
    RCT_OK(ctx, rc_sensor_create_preset(ctx, RC_PRESET_VELODYNE_VLP16, &sensor));
    RCT_OK(ctx, rc_simulate(ctx, scene, sensor, poses, 4, &buf.res));
    RCT_OK(ctx, rc_simulate(ctx, top, sensor, poses, 4, &buf.res));
    RCT_OK(ctx, rc_scene_destroy(top));
    /* a baked map: bake into the caller's block, load it in place, trace it */
    RCT_OK(ctx, rc_scene_bake(scene, NULL, 0, &blob_bytes));
    counting = 0;
    blob = rct_alloc16(blob_bytes);
    counting = 1;
    RCT_OK(ctx, rc_scene_bake(scene, blob, blob_bytes, &blob_bytes));
    RCT_OK(ctx, rc_scene_load_baked(ctx, blob, blob_bytes, 0, &baked));
    RCT_OK(ctx, rc_simulate(ctx, baked, sensor, poses, 4, &buf.res));
    RCT_OK(ctx, rc_scene_destroy(baked));
    RCT_OK(ctx, rc_sensor_destroy(sensor));
    counting = 0;

    assert_int_equal(calls, 0);
    assert_int_equal(buf.res.hits[0], 1);
    rc_context_destroy(ctx);
    free(blob);
    rct_buffers_free(&buf);
    rcu_mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_no_allocation_after_create)};
    return cmocka_run_group_tests_name("no malloc after create", tests, NULL, NULL);
}
