/* Shared fixtures for the cmocka suites: contexts per backend, scenes from
 * generated meshes, sensors from direction lists, and brute-force checks. */
#ifndef RC_TEST_H
#define RC_TEST_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "meshgen.h"
#include "rangecast/rangecast.h"

/* Fails the test with the status text and the context's last error. */
#define RCT_OK(ctx, expr)                                                                       \
    do {                                                                                        \
        rc_status rct_s_ = (expr);                                                              \
        if (rct_s_ != RC_OK)                                                                    \
            fail_msg("%s -> %s (%s)", #expr, rc_status_string(rct_s_), rc_context_last_error(ctx)); \
    } while (0)

/* Every backend id the parameterised suites run over (BVH, EMBREE, VULKAN). */
extern const uint32_t rct_backends[3];
/* A test once per backend (its state points into rct_backends), and the
 * backend a run got. */
#define RCT_FOR_BACKENDS(f)                                         \
    cmocka_unit_test_prestate(f, (void *)&rct_backends[0]),         \
        cmocka_unit_test_prestate(f, (void *)&rct_backends[1]),     \
        cmocka_unit_test_prestate(f, (void *)&rct_backends[2])
#define rct_backend_of(state) (*(const uint32_t *)*(state))

/* 1 when the backend can make a context here; prints a skip message and
 * returns 0 otherwise (the caller then calls skip()). */
int rct_backend_usable(uint32_t backend);

/* A context with a malloc'd arena of arena_mb MiB (0 = 64). */
rc_context *rct_context(uint32_t backend, uint32_t threads, size_t arena_mb);

/* A committed scene holding one referenced (or copied) mesh. */
rc_scene *rct_scene_mesh(rc_context *ctx, const rcu_mesh *mesh, uint32_t flags);
/* The same, built with build_quality (RC_BUILD_*), not yet committed. */
/* A committed scene of count referenced meshes; mesh g gets geometry id g. */
rc_scene *rct_scene_meshes(rc_context *ctx, const rcu_mesh *const *meshes, uint32_t count);
/* The same with inst_count instances of the committed scene src, instance i
 * placed by transforms[i]. */
rc_scene *rct_scene_instanced(rc_context *ctx, const rcu_mesh *const *meshes, uint32_t count, const rc_scene *src,
                              const rc_pose *transforms, uint32_t inst_count);
rc_scene *rct_scene_uncommitted(rc_context *ctx, const rcu_mesh *mesh, uint32_t flags, uint32_t build_quality);

/* rc_context_desc.backend_budget_mib on a backend that allocates outside the
 * arena (Embree: backend_bytes; Vulkan: device_bytes), with the 100k-triangle
 * sphere of radius 20 m (larger than 1 MiB on both): with 1 MiB, the commit
 * fails with RC_ERR_OUT_OF_MEMORY naming the budget, holds no more than the
 * budget (also after the failure; Vulkan holds what it held before), leaves
 * the scene uncommitted and simulate refuses it; with 64 MiB the commit
 * passes and a sensor (preset, rays a scan) at the centre sees every ray hit
 * within [19.9, 20] m. */
void rct_check_budget(uint32_t backend, uint32_t preset, uint32_t rays);

/* O1Dn sensor over n directions (copied), range [rmin, rmax]. */
rc_sensor *rct_sensor_dirs(rc_context *ctx, const float *dirs, uint32_t n, float rmin, float rmax);
/* The same with an origin per ray (OnDn; O1Dn where origins is NULL). */
rc_sensor *rct_sensor_rays(rc_context *ctx, const float *dirs, const float *origins, uint32_t n, float rmin,
                           float rmax);

/* Exact (double) intersection distance of a ray with a triangle's plane. */
double rct_ray_plane_t(const double org[3], const double dir[3], const float v0[3], const float v1[3],
                       const float v2[3]);

/* Brute-force nearest hit over all triangles in double (Möller–Trumbore with
 * an edge tolerance: for tests only). Returns the prim or UINT32_MAX. */
uint32_t rct_brute_nearest(const rcu_mesh *mesh, const double org[3], const double dir[3], double *t);

/* Identity pose with position. */
rc_pose rct_pose(float x, float y, float z);
/* Pose from position and yaw/pitch/roll (radians, ZYX). */
rc_pose rct_pose_ypr(float x, float y, float z, double yaw, double pitch, double roll);

/* Result buffers for n elements, all attributes, filled with a byte pattern. */
typedef struct rct_buffers {
    rc_results res;
    uint64_t n;
} rct_buffers;
void rct_buffers_alloc(rct_buffers *b, uint64_t n, uint32_t attributes);
void rct_buffers_fill(rct_buffers *b, unsigned char pattern);
/* 1 when every byte of every buffer is still the pattern. */
int rct_buffers_untouched(const rct_buffers *b, unsigned char pattern);
void rct_buffers_free(rct_buffers *b);
/* Every attribute of a and b (the same element count) equal byte for byte. */
void rct_assert_same_results(const rct_buffers *a, const rct_buffers *b);

/* 16-aligned heap block (posix_memalign) for caller-provided arenas. */
void *rct_alloc16(size_t size);

/* Environment switch for sanitizer/valgrind runs: smaller workloads. */
int rct_quick(void);
/* 1 when the environment variable is set to something other than "" or "0".
 * RANGECAST_VULKAN_RAY_QUERY=1 (read by the library) puts every Vulkan
 * context on the ray query traversal; RC_TEST_REQUIRE_RAY_QUERY=1 turns an
 * unusable Vulkan backend from a skip into a failure (the ray query runs of
 * tests/CMakeLists.txt). */
int rct_env_on(const char *name);

#endif
