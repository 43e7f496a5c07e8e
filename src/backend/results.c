/* What every CPU backend shares: turning one ray's nearest hit into the
 * caller's attributes (REP 117), so they agree to the bit on what they write,
 * and the ordering of a call's work on large maps (core/work_order.h; kept in
 * this object rather than its own, which measured 1.7 KB more in the static
 * library, issue 6's size budget). */
#include "backend/backend.h"
#include "bvh/intersect.h" /* RC__FORCE_INLINE */
#include "bvh/scan_raster.h" /* RC__PROJECTED_SCANS */
#include "core/work_order.h"
#if defined(RC__HIT_DISTANCES_LANES)
#include "bvh/packet.h" /* RC__PACKET_SIZE */
#endif

#include <math.h>
#include <string.h>

void rc__sensor_world_xform(const rc_sensor *sensor, const rc_pose *pose, rc__xformf *out)
{
    rc__xform base, world;
    rc__xform_from_pose(pose, &base);
    rc__xform_mul(&base, &sensor->mount_xform, &world);
    rc__xform_to_float(&world, out);
}

void rc__job_world_xform(const rc__sim_job *job, uint32_t pose, rc__xformf *out)
{
    rc__xform base, world;
    if (job->poses_d) {
        rc__xform_from_pose_d(&job->poses_d[pose], &base);
    } else {
        rc__xform_from_pose(&job->poses[pose], &base);
    }
    rc__xform_mul(&base, &job->sensor->mount_xform, &world);
    world.t[0] -= job->scene->desc.origin[0];
    world.t[1] -= job->scene->desc.origin[1];
    world.t[2] -= job->scene->desc.origin[2];
    rc__xform_to_float(&world, out);
}

/* The range REP 117 reports for a hit (or none) given its distance refined
 * in float64 (rc__scene_hit_distance_d: it removes the float rounding of
 * the traversal's t); *valid: whether it is a return within the sensor's
 * range. */
static RC__FORCE_INLINE float refined_range(const rc_sensor *sensor, int found, const rc__hit *hit, double td,
                                            int *valid)
{
    float t = found ? hit->t : 0.0f;
    /* the plane of the hit triangle in double is the better distance, also
     * for needles and slivers where the float test's t is coarse; a
     * non-positive value (origin on the plane) keeps the traversal's t */
    if (found && td > 0.0 && td < 3.0e38 && (float)td > 0.0f) t = (float)td;
    *valid = found && t >= sensor->range_min && t <= sensor->range_max;
    if (*valid) return t;
    return found && t < sensor->range_min ? -INFINITY : INFINITY;
}

#if defined(RC__HIT_DISTANCES_SSE2)
/* refined_range for four rays at once in SSE2 lanes: the same compares, the
 * same conversion and the same choices, so the same bits. range[j] gets ray
 * j's range; bit j of the result is its valid. */
static RC__FORCE_INLINE uint32_t refined_ranges4(const rc_sensor *sensor, const int *found, const rc__hit *hits,
                                                 const double *td, float range[4])
{
    const __m128d d01 = _mm_loadu_pd(td), d23 = _mm_loadu_pd(td + 2), zero_d = _mm_setzero_pd();
    const __m128d big = _mm_set1_pd(3.0e38);
    /* td > 0 && td < 3e38 as 64-bit masks, then narrowed to four 32-bit lanes */
    const __m128d ok01 = _mm_and_pd(_mm_cmpgt_pd(d01, zero_d), _mm_cmplt_pd(d01, big));
    const __m128d ok23 = _mm_and_pd(_mm_cmpgt_pd(d23, zero_d), _mm_cmplt_pd(d23, big));
    const __m128 ok = _mm_shuffle_ps(_mm_castpd_ps(ok01), _mm_castpd_ps(ok23), _MM_SHUFFLE(2, 0, 2, 0));
    const __m128 tf = _mm_movelh_ps(_mm_cvtpd_ps(d01), _mm_cvtpd_ps(d23));
    const __m128 missed = _mm_castsi128_ps(
        _mm_cmpeq_epi32(_mm_loadu_si128((const __m128i *)(const void *)found), _mm_setzero_si128()));
    /* found ? hit->t : 0, then the refined distance where it is usable */
    const __m128 t_hit = _mm_andnot_ps(missed, _mm_setr_ps(hits[0].t, hits[1].t, hits[2].t, hits[3].t));
    const __m128 use = _mm_andnot_ps(missed, _mm_and_ps(ok, _mm_cmpgt_ps(tf, _mm_setzero_ps())));
    const __m128 t = _mm_or_ps(_mm_and_ps(use, tf), _mm_andnot_ps(use, t_hit));
    const __m128 rmin = _mm_set1_ps(sensor->range_min);
    const __m128 valid =
        _mm_andnot_ps(missed, _mm_and_ps(_mm_cmpge_ps(t, rmin), _mm_cmple_ps(t, _mm_set1_ps(sensor->range_max))));
    const __m128 near = _mm_andnot_ps(missed, _mm_cmplt_ps(t, rmin));
    const __m128 none = _mm_or_ps(_mm_and_ps(near, _mm_set1_ps(-INFINITY)), _mm_andnot_ps(near, _mm_set1_ps(INFINITY)));
    _mm_storeu_ps(range, _mm_or_ps(_mm_and_ps(valid, t), _mm_andnot_ps(valid, none)));
    return (uint32_t)_mm_movemask_ps(valid);
}
#endif

/* rc__write_result given the hit's refined distance td */
static RC__FORCE_INLINE void write_refined(const rc__sim_job *job, uint64_t k, const float dir_s[3],
                                           const float *org_s, int found, const rc__hit *hit, double td,
                                           const float n_world_in[3], const rc__xformf *world)
{
    const rc_results *out = job->out;
    const uint32_t attr = job->attributes;
    int valid;
    const float range = refined_range(job->sensor, found, hit, td, &valid);

    if (attr & RC_ATTR_HITS) out->hits[k] = (uint8_t)valid;
    if (attr & RC_ATTR_RANGES) out->ranges[k] = range;
    if (attr & RC_ATTR_POINTS) {
        float *p = out->points + k * 3u;
        if (valid) {
            p[0] = dir_s[0] * range;
            p[1] = dir_s[1] * range;
            p[2] = dir_s[2] * range;
            if (org_s) {
                p[0] += org_s[0];
                p[1] += org_s[1];
                p[2] += org_s[2];
            }
        } else {
            p[0] = p[1] = p[2] = NAN;
        }
    }
    if (attr & RC_ATTR_NORMALS) {
        float *n = out->normals + k * 3u;
        if (valid) {
            float nw[3], ns[3];
            if (n_world_in) {
                memcpy(nw, n_world_in, sizeof nw);
            } else {
                rc__scene_hit_normal(job->scene, hit, nw);
            }
            rc__rot_apply_transposed_f(world->r, nw, ns);
            /* face the sensor: against the ray */
            if (rc__dot3f(ns, dir_s) > 0.0f) {
                ns[0] = -ns[0];
                ns[1] = -ns[1];
                ns[2] = -ns[2];
            }
            n[0] = ns[0];
            n[1] = ns[1];
            n[2] = ns[2];
        } else {
            n[0] = n[1] = n[2] = NAN;
        }
    }
    if (attr & RC_ATTR_PRIM_IDS) out->prim_ids[k] = valid ? hit->prim : RC_INVALID_ID;
    if (attr & RC_ATTR_GEOM_IDS) out->geom_ids[k] = valid ? hit->geom : RC_INVALID_ID;
    if (attr & RC_ATTR_INST_IDS) out->inst_ids[k] = valid ? hit->inst : RC_INVALID_ID;
}

void rc__write_result(const rc__sim_job *job, uint64_t k, const float dir_s[3], const float *org_s, int found,
                      const rc__hit *hit, const float n_world_in[3], const rc__xformf *world)
{
    write_refined(job, k, dir_s, org_s, found, hit,
                  found ? rc__scene_hit_distance_d(job->scene, hit, world, dir_s, org_s) : 0.0, n_world_in, world);
}

/* Rays idx[i] (or first + i where idx is NULL) of one pose of a one-origin
 * sensor, element base + ray, with their refined distances td[i]. */
static RC__FORCE_INLINE void write_rays(const rc__sim_job *job, uint64_t base, const uint32_t *idx, uint32_t first,
                                        uint32_t n, const int *found, const rc__hit *hits, const double *td,
                                        const rc__xformf *world)
{
    const float *directions = job->sensor->directions;
    uint32_t i;
    if (!(job->attributes & (RC_ATTR_POINTS | RC_ATTR_NORMALS))) {
        /* hits, ranges and ids (a localisation filter's call): without
         * write_refined's tests of every attribute a ray */
        const uint32_t attr = job->attributes;
        const rc_results *out = job->out;
        uint8_t *const hit_out = attr & RC_ATTR_HITS ? out->hits : NULL;
        float *const range_out = attr & RC_ATTR_RANGES ? out->ranges : NULL;
        uint32_t *const prim_out = attr & RC_ATTR_PRIM_IDS ? out->prim_ids : NULL;
        uint32_t *const geom_out = attr & RC_ATTR_GEOM_IDS ? out->geom_ids : NULL;
        uint32_t *const inst_out = attr & RC_ATTR_INST_IDS ? out->inst_ids : NULL;
        i = 0;
#if defined(RC__HIT_DISTANCES_SSE2)
        /* four rays' ranges at once (refined_ranges4), then each requested
         * attribute stored for the four */
        for (; i + 4u <= n; i += 4u) {
            float range[4];
            const uint32_t valid = refined_ranges4(job->sensor, found + i, hits + i, td + i, range);
            uint64_t k[4];
            uint32_t j;
            for (j = 0; j < 4u; ++j) k[j] = base + (idx ? idx[i + j] : first + i + j);
            if (range_out)
                for (j = 0; j < 4u; ++j) range_out[k[j]] = range[j];
            if (hit_out)
                for (j = 0; j < 4u; ++j) hit_out[k[j]] = (uint8_t)((valid >> j) & 1u);
            if (prim_out)
                for (j = 0; j < 4u; ++j) prim_out[k[j]] = (valid >> j) & 1u ? hits[i + j].prim : RC_INVALID_ID;
            if (geom_out)
                for (j = 0; j < 4u; ++j) geom_out[k[j]] = (valid >> j) & 1u ? hits[i + j].geom : RC_INVALID_ID;
            if (inst_out)
                for (j = 0; j < 4u; ++j) inst_out[k[j]] = (valid >> j) & 1u ? hits[i + j].inst : RC_INVALID_ID;
        }
#endif
        for (; i < n; ++i) {
            const uint64_t k = base + (idx ? idx[i] : first + i);
            int valid;
            const float range = refined_range(job->sensor, found[i], &hits[i], td[i], &valid);
            if (hit_out) hit_out[k] = (uint8_t)valid;
            if (range_out) range_out[k] = range;
            if (prim_out) prim_out[k] = valid ? hits[i].prim : RC_INVALID_ID;
            if (geom_out) geom_out[k] = valid ? hits[i].geom : RC_INVALID_ID;
            if (inst_out) inst_out[k] = valid ? hits[i].inst : RC_INVALID_ID;
        }
        return;
    }
    for (i = 0; i < n; ++i) {
        const uint32_t ray = idx ? idx[i] : first + i;
        write_refined(job, base + ray, directions + (size_t)ray * 3u, NULL, found[i], &hits[i], td[i], NULL, world);
    }
}

#if defined(RC__PROJECTED_SCANS)
void rc__write_results_run(const rc__sim_job *job, uint64_t base, uint32_t first, uint32_t n, const int *found,
                           const rc__hit *hits, const double *td, const rc__xformf *world)
{
    write_rays(job, base, NULL, first, n, found, hits, td, world);
}
#endif

#if defined(RC__HIT_DISTANCES_LANES)
void rc__write_results_tile(const rc__sim_job *job, uint64_t base, const uint32_t *idx, uint32_t n, const int *found,
                            const rc__hit *hits, const rc__xformf *world)
{
    double td[RC__PACKET_SIZE];
    rc__scene_hit_distances_d(job->scene, hits, found, n, world, job->sensor->directions, idx, td);
    write_rays(job, base, idx, 0u, n, found, hits, td, world);
}
#endif

/* Ordered runs (core/work_order.h). */

/* what RC_SIMULATE_SCRATCH_PER_THREAD promises: the largest scratch (the
 * backends keep an rc__xformf a pose), the arena's header and rounding */
typedef char rc__order_scratch_bound_check[(RC__ORDER_MAX_RECORDS * 16u + 16u +
                                                RC__ORDER_MAX_POSES * sizeof(rc__xformf) + 32u <=
                                            RC_SIMULATE_SCRATCH_PER_THREAD)
                                               ? 1
                                               : -1];

void rc__radix_sort_pairs(uint32_t *keys, uint32_t *values, uint32_t *tmp_keys, uint32_t *tmp_values, uint32_t n,
                          uint32_t bits)
{
    uint32_t *src_k = keys, *src_v = values, *dst_k = tmp_keys, *dst_v = tmp_values, *t;
    uint32_t shift, passes = 0;
    if (bits > 32u) bits = 32u;
    for (shift = 0; shift < bits; shift += 8u, ++passes) {
        uint32_t start[256], i, sum = 0;
        memset(start, 0, sizeof start);
        for (i = 0; i < n; ++i) ++start[(src_k[i] >> shift) & 255u];
        for (i = 0; i < 256u; ++i) {
            const uint32_t count = start[i];
            start[i] = sum;
            sum += count;
        }
        for (i = 0; i < n; ++i) {
            const uint32_t at = start[(src_k[i] >> shift) & 255u]++;
            dst_k[at] = src_k[i];
            dst_v[at] = src_v[i];
        }
        t = src_k, src_k = dst_k, dst_k = t;
        t = src_v, src_v = dst_v, dst_v = t;
    }
    /* an odd number of passes left the result in the tmp arrays */
    if (passes & 1u) {
        memcpy(keys, tmp_keys, (size_t)n * sizeof *keys);
        memcpy(values, tmp_values, (size_t)n * sizeof *values);
    }
}
