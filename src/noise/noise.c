/* Range noise and dropout over the host results (see noise.h). The
 * generator is splitmix64's output function on a counter: element k of
 * draw d of seed s uses indices 3k, 3k+1, 3k+2 of key(s, d), so no state
 * is shared between threads and the result depends on nothing else. */
#include "noise/noise.h"

#include <math.h>
#include <string.h>

#define GOLDEN 0x9E3779B97F4A7C15ull

static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

uint64_t rc__noise_key(uint64_t seed, uint64_t draw) { return mix64(seed ^ mix64(draw * GOLDEN + 1u)); }

double rc__noise_uniform(uint64_t key, uint64_t index)
{
    /* 53 random bits, shifted off zero: log() below never sees 0 */
    return (double)((mix64(key + (index + 1u) * GOLDEN) >> 11) + 1u) * (1.0 / 9007199254740992.0);
}

double rc__noise_normal(uint64_t key, uint64_t index)
{
    /* Box-Muller with one of its two outputs, in float: half the time of
     * double (19 against 33 ns here), and 24-bit uniforms still reach
     * 5.8 standard deviations, far past what a range model needs */
    const float u1 = (float)rc__noise_uniform(key, index), u2 = (float)rc__noise_uniform(key, index + 1u);
    return (double)(sqrtf(-2.0f * logf(u1)) * cosf(6.2831853f * u2));
}

rc_status rc__noise_check(rc_context *ctx, const rc_noise_desc *desc)
{
    RC_TRY(rc__check_desc(ctx, desc, (uint32_t)sizeof *desc, (uint32_t)sizeof *desc, "noise"));
    RC_TRY(rc__check_reserved(ctx, desc->reserved, sizeof desc->reserved / sizeof desc->reserved[0], "noise"));
    RC_RETURN_IF(ctx, desc->reserved0 != 0, RC_ERR_INVALID_ARGUMENT, "noise->reserved0 is %u; it must be 0",
                 (unsigned)desc->reserved0);
    RC_RETURN_IF(ctx, !isfinite(desc->mean), RC_ERR_NON_FINITE, "noise->mean is %g; it must be finite",
                 (double)desc->mean);
    RC_RETURN_IF(ctx, !isfinite(desc->sigma), RC_ERR_NON_FINITE, "noise->sigma is %g; it must be finite",
                 (double)desc->sigma);
    RC_RETURN_IF(ctx, !isfinite(desc->sigma_exponent), RC_ERR_NON_FINITE,
                 "noise->sigma_exponent is %g; it must be finite", (double)desc->sigma_exponent);
    RC_RETURN_IF(ctx, !isfinite(desc->dropout), RC_ERR_NON_FINITE, "noise->dropout is %g; it must be finite",
                 (double)desc->dropout);
    RC_RETURN_IF(ctx, desc->sigma < 0.0f, RC_ERR_INVALID_ARGUMENT, "noise->sigma is %g; it must be >= 0",
                 (double)desc->sigma);
    RC_RETURN_IF(ctx, desc->sigma_exponent < 0.0f, RC_ERR_INVALID_ARGUMENT,
                 "noise->sigma_exponent is %g; it must be >= 0", (double)desc->sigma_exponent);
    RC_RETURN_IF(ctx, desc->dropout < 0.0f || desc->dropout > 1.0f, RC_ERR_INVALID_ARGUMENT,
                 "noise->dropout is %g; it is a probability in [0, 1]", (double)desc->dropout);
    return RC_OK;
}

void rc__noise_set(rc__noise *noise, const rc_noise_desc *desc)
{
    memset(noise, 0, sizeof *noise);
    if (!desc) return;
    noise->mean = desc->mean;
    noise->sigma = desc->sigma;
    noise->exponent = desc->sigma_exponent;
    noise->dropout = desc->dropout;
    noise->seed = desc->seed;
    noise->enabled = desc->mean != 0.0f || desc->sigma != 0.0f || desc->dropout != 0.0f;
}

typedef struct noise_run {
    const rc__noise *noise;
    const rc__noise_job *job;
    uint64_t key;
} noise_run;

/* 1 when element k is a return, judged by the first requested attribute that
 * tells; -1 when none does (inst_ids alone). */
static int is_return(const rc_results *out, uint32_t a, uint64_t k)
{
    if (a & RC_ATTR_HITS) return out->hits[k] != 0;
    if (a & RC_ATTR_RANGES) return isfinite(out->ranges[k]) != 0;
    if (a & RC_ATTR_POINTS) return out->points[3u * k] == out->points[3u * k];
    if (a & RC_ATTR_NORMALS) return out->normals[3u * k] == out->normals[3u * k];
    if (a & RC_ATTR_PRIM_IDS) return out->prim_ids[k] != RC_INVALID_ID;
    if (a & RC_ATTR_GEOM_IDS) return out->geom_ids[k] != RC_INVALID_ID;
    return -1;
}

static void lose(const rc_results *out, uint32_t a, uint64_t k)
{
    if (a & RC_ATTR_HITS) out->hits[k] = 0;
    if (a & RC_ATTR_RANGES) out->ranges[k] = INFINITY;
    if (a & RC_ATTR_POINTS) out->points[3u * k] = out->points[3u * k + 1u] = out->points[3u * k + 2u] = NAN;
    if (a & RC_ATTR_NORMALS) out->normals[3u * k] = out->normals[3u * k + 1u] = out->normals[3u * k + 2u] = NAN;
    if (a & RC_ATTR_PRIM_IDS) out->prim_ids[k] = RC_INVALID_ID;
    if (a & RC_ATTR_GEOM_IDS) out->geom_ids[k] = RC_INVALID_ID;
    if (a & RC_ATTR_INST_IDS) out->inst_ids[k] = RC_INVALID_ID;
}

/* Moves return k from range r to r + noise (clamped to the sensor's range). */
static void move(const noise_run *run, uint64_t k, uint32_t ray)
{
    const rc__noise *nz = run->noise;
    const rc__noise_job *job = run->job;
    const rc_results *out = job->out;
    const float *org = job->origins ? job->origins + 3u * ray : NULL;
    float *p = (job->attributes & RC_ATTR_POINTS) ? out->points + 3u * k : NULL;
    double r, scale, spread, moved;
    uint32_t i;
    if (job->attributes & RC_ATTR_RANGES) {
        r = out->ranges[k];
    } else if (p) {
        double d2 = 0.0;
        for (i = 0; i < 3; ++i) {
            const double d = (double)p[i] - (org ? org[i] : 0.0f);
            d2 += d * d;
        }
        r = sqrt(d2);
    } else {
        return; /* neither ranges nor points: nothing shows the range */
    }
    scale = nz->exponent == 0.0f ? 1.0 : nz->exponent == 1.0f ? r : pow(r, (double)nz->exponent);
    spread = (double)nz->sigma * scale * rc__noise_normal(run->key, 3u * k);
    /* an infinite sigma * r^k times a variate of exactly 0 (u1 rounds to 1
     * in float about once in 3e7 draws) is NaN: no spread then; an infinite
     * spread is clamped below like any other */
    if (spread != spread) spread = 0.0;
    moved = r + (double)nz->mean + spread;
    if (moved < (double)job->range_min) moved = job->range_min;
    if (moved > (double)job->range_max) moved = job->range_max;
    if (job->attributes & RC_ATTR_RANGES) out->ranges[k] = (float)moved;
    if (p && r > 0.0) {
        const double f = moved / r;
        for (i = 0; i < 3; ++i) {
            const double o = org ? org[i] : 0.0f;
            p[i] = (float)(o + ((double)p[i] - o) * f);
        }
    }
}

static void noise_task(void *user, uint32_t pose, uint32_t thread)
{
    const noise_run *run = (const noise_run *)user;
    const rc__noise *nz = run->noise;
    const rc__noise_job *job = run->job;
    const int moves = nz->mean != 0.0f || nz->sigma != 0.0f;
    uint32_t ray;
    (void)thread;
    for (ray = 0; ray < job->rays; ++ray) {
        const uint64_t k = (uint64_t)pose * job->rays + ray;
        if (is_return(job->out, job->attributes, k) != 1) continue;
        if (nz->dropout > 0.0f && rc__noise_uniform(run->key, 3u * k + 2u) <= (double)nz->dropout) {
            lose(job->out, job->attributes, k);
            continue;
        }
        if (moves) move(run, k, ray);
    }
}

void rc__noise_apply(rc__pool *pool, const rc__noise *noise, const rc__noise_job *job)
{
    noise_run run;
    if (!noise->enabled) return;
    run.noise = noise;
    run.job = job;
    run.key = rc__noise_key(noise->seed, noise->draws);
    rc__pool_run(pool, job->pose_count, noise_task, &run);
}
