/* rc__rays_prepare_turned (SSE2 / AArch64 NEON, four rays at a time; eight
 * in AVX where the CPU has AVX2) gives every ray exactly what the per-ray
 * path gives: the turned direction, its reciprocal, the dominant axis, the
 * winding swap and the shear constants, bit for bit, for random turns and
 * directions, axis-aligned and diagonal ones (zeros, -0, ties between
 * components), through an index table, and for counts that are not a
 * multiple of four or eight. */
#include <math.h>
#include <string.h>

#include "bvh/mesh.h"
#include "core/rmath.h"
#include "rc_test.h"

static uint64_t rng = 0x9E3779B97F4A7C15ull;
static double uniform(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}

/* A row-major rotation from a random unit quaternion; every 4th one the
 * identity and every 4th + 1 a quarter turn about z (exact zeros survive). */
static void random_turn(uint32_t k, float r[9])
{
    double q[4], n = 0.0;
    int i;
    if (k % 4 == 0 || k % 4 == 1) {
        static const float id[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, qz[9] = {0, -1, 0, 1, 0, 0, 0, 0, 1};
        memcpy(r, k % 4 == 0 ? id : qz, sizeof id);
        return;
    }
    for (i = 0; i < 4; ++i) {
        q[i] = uniform() * 2.0 - 1.0;
        n += q[i] * q[i];
    }
    n = sqrt(n);
    for (i = 0; i < 4; ++i) q[i] /= n;
    r[0] = (float)(1 - 2 * (q[1] * q[1] + q[2] * q[2]));
    r[1] = (float)(2 * (q[0] * q[1] - q[2] * q[3]));
    r[2] = (float)(2 * (q[0] * q[2] + q[1] * q[3]));
    r[3] = (float)(2 * (q[0] * q[1] + q[2] * q[3]));
    r[4] = (float)(1 - 2 * (q[0] * q[0] + q[2] * q[2]));
    r[5] = (float)(2 * (q[1] * q[2] - q[0] * q[3]));
    r[6] = (float)(2 * (q[0] * q[2] - q[1] * q[3]));
    r[7] = (float)(2 * (q[1] * q[2] + q[0] * q[3]));
    r[8] = (float)(1 - 2 * (q[0] * q[0] + q[1] * q[1]));
}

#define DIRS 96u

/* Sensor-frame directions: random ones, then the 26 axis, face-diagonal and
 * space-diagonal directions with +-0 components, then ties of magnitude. */
static void make_dirs(float *d)
{
    uint32_t i = 0;
    int x, y, z;
    for (x = -1; x <= 1; ++x)
        for (y = -1; y <= 1; ++y)
            for (z = -1; z <= 1; ++z) {
                if (!x && !y && !z) continue;
                d[3 * i] = x ? (float)x : (i % 2 ? -0.0f : 0.0f);
                d[3 * i + 1] = (float)y;
                d[3 * i + 2] = z ? (float)z : -0.0f;
                ++i;
            }
    for (; i < 40u; ++i) { /* |x| == |y| > |z|, and |y| == |z| > |x| */
        const float a = (float)(0.5 + uniform()), b = (float)(uniform() * 0.4);
        d[3 * i] = i % 2 ? a : b;
        d[3 * i + 1] = i % 3 ? -a : a;
        d[3 * i + 2] = i % 2 ? b : -a;
    }
    for (; i < DIRS; ++i) {
        d[3 * i] = (float)(uniform() * 2.0 - 1.0);
        d[3 * i + 1] = (float)(uniform() * 2.0 - 1.0);
        d[3 * i + 2] = (float)(uniform() * 2.0 - 1.0);
        if (i % 9 == 0) d[3 * i + 2] = 0.0f; /* a 2-D scanner's ray */
    }
}

static void test_batch_equals_per_ray(void **state)
{
    float dirs[DIRS * 3], r[9];
    uint32_t idx[DIRS], k, i, n;
    rc__ray got[DIRS], want;
    (void)state;
    make_dirs(dirs);
    for (k = 0; k < 200u; ++k) {
        const float org[3] = {(float)(uniform() * 20.0 - 10.0), (float)(uniform() * 20.0 - 10.0), 1.5f};
        random_turn(k, r);
        n = 1u + (uint32_t)(uniform() * DIRS) % DIRS; /* 1 .. DIRS, any remainder mod 4 */
        for (i = 0; i < n; ++i) idx[i] = k % 2 ? i : (uint32_t)(uniform() * DIRS) % DIRS;
        memset(got, 0x5a, sizeof got);
        rc__rays_prepare_turned(r, org, dirs, idx, n, got);
        for (i = 0; i < n; ++i) {
            float dir[3];
            memset(&want, 0x5a, sizeof want);
            rc__rot_apply_f(r, dirs + 3u * idx[i], dir);
            rc__ray_prepare(&want, org, dir);
            assert_memory_equal(&got[i], &want, sizeof want);
        }
        for (; i < DIRS; ++i) { /* nothing past n is written */
            memset(&want, 0x5a, sizeof want);
            assert_memory_equal(&got[i], &want, sizeof want);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_batch_equals_per_ray)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
