#include "poses.h"
#include "tum.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define RCU_PI 3.14159265358979323846

static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

void rcu_rng_seed(rcu_rng *rng, uint64_t seed)
{
    int i;
    for (i = 0; i < 4; i++) rng->s[i] = splitmix64(&seed);
}

static uint64_t rotl(uint64_t x, int k)
{
    return (x << k) | (x >> (64 - k));
}

uint64_t rcu_rng_next(rcu_rng *rng)
{
    uint64_t *s = rng->s;
    uint64_t result = rotl(s[1] * 5u, 7) * 9u;
    uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return result;
}

double rcu_rng_uniform(rcu_rng *rng)
{
    return (double)(rcu_rng_next(rng) >> 11) * (1.0 / 9007199254740992.0);
}

void rcu_poses_random(uint32_t count, float radius, uint64_t seed, rc_pose *out)
{
    rcu_poses_random_about(count, radius, seed, NULL, out);
}

/* A point uniform in the unit ball (rejection sampling in the cube). */
static void unit_ball(rcu_rng *rng, double p[3])
{
    do {
        p[0] = 2.0 * rcu_rng_uniform(rng) - 1.0;
        p[1] = 2.0 * rcu_rng_uniform(rng) - 1.0;
        p[2] = 2.0 * rcu_rng_uniform(rng) - 1.0;
    } while (p[0] * p[0] + p[1] * p[1] + p[2] * p[2] > 1.0);
}

void rcu_poses_random_about(uint32_t count, float radius, uint64_t seed, const float center[3],
                            rc_pose *out)
{
    rcu_rng rng;
    uint32_t i;
    rcu_rng_seed(&rng, seed);
    for (i = 0; i < count; i++) {
        double p[3], u1, u2, u3, a, b;
        /* no transcendental functions: the positions are bit-identical everywhere */
        unit_ball(&rng, p);
        out[i].position[0] = (float)(p[0] * radius + (center ? center[0] : 0.0f));
        out[i].position[1] = (float)(p[1] * radius + (center ? center[1] : 0.0f));
        out[i].position[2] = (float)(p[2] * radius + (center ? center[2] : 0.0f));
        /* Shoemake 1992, "Uniform random rotations" */
        u1 = rcu_rng_uniform(&rng);
        u2 = rcu_rng_uniform(&rng);
        u3 = rcu_rng_uniform(&rng);
        a = sqrt(1.0 - u1);
        b = sqrt(u1);
        out[i].orientation[0] = (float)(a * sin(2.0 * RCU_PI * u2));
        out[i].orientation[1] = (float)(a * cos(2.0 * RCU_PI * u2));
        out[i].orientation[2] = (float)(b * sin(2.0 * RCU_PI * u3));
        out[i].orientation[3] = (float)(b * cos(2.0 * RCU_PI * u3));
    }
}

double rcu_pose_quaternion_norm(const rc_pose *pose)
{
    const float *q = pose->orientation;
    return sqrt((double)q[0] * q[0] + (double)q[1] * q[1] + (double)q[2] * q[2] + (double)q[3] * q[3]);
}

int rcu_poses_is_tum(const char *path)
{
    char ext[8];
    rcu_path_extension(path, ext, sizeof ext);
    return strcmp(ext, "tum") == 0 || strcmp(ext, "txt") == 0;
}

int rcu_poses_read(const char *path, rc_pose **out, uint32_t *count)
{
    unsigned char *data;
    size_t size, n, i;
    rc_pose *poses;
    if (rcu_poses_is_tum(path)) return rcu_tum_read(path, out, count);
    if (rcu_read_file(path, &data, &size) != 0) return -1;
    if (size == 0) {
        free(data);
        return rcu_fail("%s: empty pose file (expected 28 bytes a pose: 7 little-endian float32 "
                        "x y z qx qy qz qw)", path);
    }
    if (size % RCU_POSE_FILE_BYTES != 0) {
        free(data);
        return rcu_fail("%s: size %zu bytes is not a multiple of 28 (7 little-endian float32 "
                        "x y z qx qy qz qw per pose); %zu bytes left over",
                        path, size, size % RCU_POSE_FILE_BYTES);
    }
    n = size / RCU_POSE_FILE_BYTES;
    if (n > UINT32_MAX) {
        free(data);
        return rcu_fail("%s: too many poses (%zu)", path, n);
    }
    poses = (rc_pose *)malloc(n * sizeof *poses);
    if (!poses) {
        free(data);
        return rcu_fail("%s: out of memory for %zu poses", path, n);
    }
    for (i = 0; i < n; i++) {
        const unsigned char *p = data + i * RCU_POSE_FILE_BYTES;
        double norm;
        int k;
        for (k = 0; k < 3; k++) poses[i].position[k] = rcu_load_f32le(p + 4 * k);
        for (k = 0; k < 4; k++) poses[i].orientation[k] = rcu_load_f32le(p + 12 + 4 * k);
        norm = rcu_pose_quaternion_norm(&poses[i]);
        for (k = 0; k < 3; k++)
            if (!isfinite(poses[i].position[k])) break;
        if (k < 3 || !isfinite(norm)) {
            free(data);
            free(poses);
            return rcu_fail("%s: pose %zu (byte offset %zu) has a NaN or infinite value", path, i,
                            i * RCU_POSE_FILE_BYTES);
        }
        if (fabs(norm - 1.0) > RCU_POSE_NORM_TOLERANCE) {
            rcu_fail("%s: pose %zu (byte offset %zu): quaternion (%g, %g, %g, %g) has norm %g, "
                     "not 1 (is the file x y z qx qy qz qw float32 little-endian?)",
                     path, i, i * RCU_POSE_FILE_BYTES, (double)poses[i].orientation[0],
                     (double)poses[i].orientation[1], (double)poses[i].orientation[2],
                     (double)poses[i].orientation[3], norm);
            free(data);
            free(poses);
            return -1;
        }
    }
    free(data);
    *out = poses;
    *count = (uint32_t)n;
    return 0;
}

int rcu_poses_write(const char *path, const rc_pose *poses, uint32_t count)
{
    FILE *f;
    uint32_t i;
    if (rcu_poses_is_tum(path)) return rcu_tum_write(path, poses, count, RCU_TUM_PERIOD);
    f = fopen(path, "wb");
    if (!f) return rcu_fail("%s: %s", path, strerror(errno));
    for (i = 0; i < count; i++) {
        unsigned char rec[RCU_POSE_FILE_BYTES];
        int k;
        for (k = 0; k < 3; k++) rcu_store_f32le(rec + 4 * k, poses[i].position[k]);
        for (k = 0; k < 4; k++) rcu_store_f32le(rec + 12 + 4 * k, poses[i].orientation[k]);
        if (fwrite(rec, 1, sizeof rec, f) != sizeof rec) {
            fclose(f);
            rcu_remove_partial(path);
            return rcu_fail("%s: write error", path);
        }
    }
    if (fclose(f) != 0) {
        rcu_remove_partial(path);
        return rcu_fail("%s: write error", path);
    }
    return 0;
}

void rcu_rays_random(uint32_t count, float radius, uint64_t seed, float *origins, float *dirs)
{
    rcu_rng rng;
    uint32_t i;
    int k;
    rcu_rng_seed(&rng, seed);
    for (i = 0; i < count; i++) {
        double o[3], d[3], n;
        unit_ball(&rng, o);
        do { /* a direction: a ball point not too near the centre, normalised */
            unit_ball(&rng, d);
            n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        } while (n < 1e-3);
        for (k = 0; k < 3; k++) {
            origins[3u * i + (uint32_t)k] = (float)(o[k] * radius);
            dirs[3u * i + (uint32_t)k] = (float)(d[k] / n);
        }
    }
}
