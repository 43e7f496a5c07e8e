/* Range noise and dropout (rc_sensor_set_noise): one pass over the host
 * results after the backend traced them, so every backend and thread count
 * gets the same numbers from the same counter-based generator. Results kept
 * on the device get the same generator in the Vulkan kernel
 * (kernels/noise.glsl, keep the two in step). */
#ifndef RC_NOISE_NOISE_H
#define RC_NOISE_NOISE_H

#include "core/context.h"

typedef struct rc__noise { /* struct tag: backend.h forward-declares it */
    int enabled;          /* 0: simulate skips the pass */
    float mean, sigma, exponent, dropout;
    uint64_t seed;
    uint64_t draws;       /* successful simulates since the noise was set */
} rc__noise;

/* What the pass needs of one simulate call. */
typedef struct rc__noise_job {
    const rc_results *out;
    uint32_t attributes;
    uint32_t pose_count, rays;
    const float *origins;  /* 3 per ray (OnDn), else NULL: rays start at the sensor */
    float range_min, range_max;
} rc__noise_job;

/* Checks a desc (messages name the field). */
rc_status rc__noise_check(rc_context *ctx, const rc_noise_desc *desc);
/* Sets noise from a checked desc (NULL: none) and restarts the draw count. */
void rc__noise_set(rc__noise *noise, const rc_noise_desc *desc);
/* Applies draw noise->draws to the job's buffers on the pool's threads. */
void rc__noise_apply(rc__pool *pool, const rc__noise *noise, const rc__noise_job *job);

/* The generator, for tests: a uniform in (0, 1] and a standard normal of
 * (key, index), and the key of (seed, draw). */
uint64_t rc__noise_key(uint64_t seed, uint64_t draw);
double rc__noise_uniform(uint64_t key, uint64_t index);
double rc__noise_normal(uint64_t key, uint64_t index);

#endif
