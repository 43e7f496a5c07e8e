/* The hand-written baseline: one rtcIntersect1 per ray in a pthread
 * parallel-for over poses (see embree_single.h). Deliberately plain: what a
 * user writes from Embree's tutorial, so `rangecast bench` can show what the
 * packet path of rangecast's Embree backend buys. */
#include "embree_single.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util.h"

#if defined(RANGECAST_EMBREE_MAJOR) && RANGECAST_EMBREE_MAJOR >= 4
#include <embree4/rtcore.h>
#else
#include <embree3/rtcore.h>
#endif

typedef struct single_job {
    RTCScene scene;
    const float *directions;
    const float *origins;   /* NULL: the pose's position */
    uint32_t ray_count;
    float range_min, range_max;
    const rc_pose *poses;
    uint32_t first, last;   /* this thread's poses */
    int repeat;
    float *ranges_out;
} single_job;

/* Row-major rotation of a (normalised) quaternion x y z w. */
static void quat_matrix(const float q_in[4], float r[9])
{
    double x = q_in[0], y = q_in[1], z = q_in[2], w = q_in[3];
    double n = sqrt(x * x + y * y + z * z + w * w);
    if (n > 0.0) {
        x /= n;
        y /= n;
        z /= n;
        w /= n;
    }
    r[0] = (float)(1 - 2 * (y * y + z * z));
    r[1] = (float)(2 * (x * y - z * w));
    r[2] = (float)(2 * (x * z + y * w));
    r[3] = (float)(2 * (x * y + z * w));
    r[4] = (float)(1 - 2 * (x * x + z * z));
    r[5] = (float)(2 * (y * z - x * w));
    r[6] = (float)(2 * (x * z - y * w));
    r[7] = (float)(2 * (y * z + x * w));
    r[8] = (float)(1 - 2 * (x * x + y * y));
}

static void *single_worker(void *arg)
{
    const single_job *job = (const single_job *)arg;
    int rep;
#if RTC_VERSION_MAJOR < 4
    struct RTCIntersectContext context;
    rtcInitIntersectContext(&context);
#endif
    for (rep = 0; rep < job->repeat; ++rep) {
        uint32_t p, i;
        for (p = job->first; p < job->last; ++p) {
            const rc_pose *pose = &job->poses[p];
            float r[9];
            quat_matrix(pose->orientation, r);
            for (i = 0; i < job->ray_count; ++i) {
                const float *d = job->directions + (size_t)i * 3u;
                struct RTCRayHit rh;
                float range;
                rh.ray.org_x = pose->position[0];
                rh.ray.org_y = pose->position[1];
                rh.ray.org_z = pose->position[2];
                if (job->origins) {
                    const float *o = job->origins + (size_t)i * 3u;
                    rh.ray.org_x += r[0] * o[0] + r[1] * o[1] + r[2] * o[2];
                    rh.ray.org_y += r[3] * o[0] + r[4] * o[1] + r[5] * o[2];
                    rh.ray.org_z += r[6] * o[0] + r[7] * o[1] + r[8] * o[2];
                }
                rh.ray.dir_x = r[0] * d[0] + r[1] * d[1] + r[2] * d[2];
                rh.ray.dir_y = r[3] * d[0] + r[4] * d[1] + r[5] * d[2];
                rh.ray.dir_z = r[6] * d[0] + r[7] * d[1] + r[8] * d[2];
                rh.ray.tnear = 0.0f;
                rh.ray.tfar = job->range_max;
                rh.ray.time = 0.0f;
                rh.ray.mask = 0xFFFFFFFFu;
                rh.ray.id = 0;
                rh.ray.flags = 0;
                rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
#if RTC_VERSION_MAJOR >= 4
                rtcIntersect1(job->scene, &rh, NULL);
#else
                rtcIntersect1(job->scene, &context, &rh);
#endif
                if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
                    range = INFINITY;
                else if (rh.ray.tfar < job->range_min)
                    range = -INFINITY;
                else
                    range = rh.ray.tfar;
                if (job->ranges_out) job->ranges_out[(size_t)p * job->ray_count + i] = range;
            }
        }
    }
    return NULL;
}

static int embree_failed(RTCDevice device, const char *what)
{
    enum RTCError e = rtcGetDeviceError(device);
    return rcu_fail("embree-single: %s failed (RTCError %d)", what, (int)e);
}

int rct_embree_single_bench(const float *vertices, uint32_t vertex_count, const uint32_t *indices,
                            uint32_t triangle_count, const float *directions, const float *origins,
                            uint32_t ray_count,
                            float range_min, float range_max, const rc_pose *poses, uint32_t pose_count,
                            uint32_t threads, int repeat, double *scans_per_s, double *build_s,
                            float *ranges_out)
{
    char config[64];
    RTCDevice device;
    RTCScene scene;
    RTCGeometry geom;
    float *vb;
    uint32_t *ib;
    single_job *jobs;
    pthread_t *tids;
    uint32_t t, started = 0;
    double t0, t1;
    int rc = 0;

    if (!vertices || !indices || !directions || !poses || !scans_per_s || !build_s)
        return rcu_fail("embree-single: a required pointer is NULL");
    if (vertex_count == 0 || triangle_count == 0 || ray_count == 0 || pose_count == 0 || threads == 0 ||
        repeat < 1)
        return rcu_fail("embree-single: counts, threads and repeat must be at least 1");
    if (!(range_max > range_min) || range_min < 0.0f)
        return rcu_fail("embree-single: need 0 <= range_min < range_max");
    if (threads > pose_count) threads = pose_count;

    t0 = rcu_now();
    snprintf(config, sizeof config, "threads=%u", (unsigned)threads);
    device = rtcNewDevice(config);
    if (!device) return rcu_fail("embree-single: rtcNewDevice failed (RTCError %d)", (int)rtcGetDeviceError(NULL));
    scene = rtcNewScene(device);
    geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    vb = (float *)rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                          vertex_count);
    ib = (uint32_t *)rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                             3 * sizeof(uint32_t), triangle_count);
    if (!vb || !ib) {
        rc = embree_failed(device, "rtcSetNewGeometryBuffer");
        rtcReleaseGeometry(geom);
        rtcReleaseScene(scene);
        rtcReleaseDevice(device);
        return rc;
    }
    memcpy(vb, vertices, (size_t)vertex_count * 3u * sizeof(float));
    memcpy(ib, indices, (size_t)triangle_count * 3u * sizeof(uint32_t));
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(scene);
    if (rtcGetDeviceError(device) != RTC_ERROR_NONE) {
        rc = rcu_fail("embree-single: building the scene failed");
        rtcReleaseScene(scene);
        rtcReleaseDevice(device);
        return rc;
    }
    *build_s = rcu_now() - t0;

    jobs = (single_job *)calloc(threads, sizeof *jobs);
    tids = (pthread_t *)calloc(threads, sizeof *tids);
    if (!jobs || !tids) {
        free(jobs);
        free(tids);
        rtcReleaseScene(scene);
        rtcReleaseDevice(device);
        return rcu_fail("embree-single: out of memory");
    }
    for (t = 0; t < threads; ++t) {
        jobs[t].scene = scene;
        jobs[t].directions = directions;
        jobs[t].origins = origins;
        jobs[t].ray_count = ray_count;
        jobs[t].range_min = range_min;
        jobs[t].range_max = range_max;
        jobs[t].poses = poses;
        jobs[t].first = (uint32_t)((uint64_t)pose_count * t / threads);
        jobs[t].last = (uint32_t)((uint64_t)pose_count * (t + 1u) / threads);
        jobs[t].repeat = repeat;
        jobs[t].ranges_out = ranges_out;
    }
    t0 = rcu_now();
    /* the calling thread takes the first share, as a parallel-for does */
    for (t = 1; t < threads; ++t) {
        if (pthread_create(&tids[t], NULL, single_worker, &jobs[t]) != 0) {
            rc = rcu_fail("embree-single: pthread_create failed");
            break;
        }
        started = t;
    }
    single_worker(&jobs[0]);
    for (t = 1; t <= started; ++t) pthread_join(tids[t], NULL);
    t1 = rcu_now();
    if (rc == 0) *scans_per_s = (double)pose_count * repeat / (t1 - t0 > 0.0 ? t1 - t0 : 1e-9);
    free(jobs);
    free(tids);
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
    return rc;
}
