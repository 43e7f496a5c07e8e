/* rangecast: range noise and dropout in the kernel, for results kept on the
 * device (RC_RESULTS_ON_DEVICE). A port of src/noise/noise.c; keep them in
 * step. Host results get the host's pass instead (every backend alike).
 *
 * The generator is splitmix64's output function on a counter, in 64-bit
 * arithmetic made of 32-bit words (no shaderInt64 needed), so the uniforms
 * and the dropout decisions are the host's, bit for bit. The normal variate
 * is Box-Muller in float from the same uniforms, as on the host: with
 * float64 (RC_FP64 1) its log and cos are computed here in double and rounded
 * to float, which gives what the host's libm gives but for a last-bit
 * difference at most; without float64 GLSL's own log and cos are used, whose
 * error Vulkan bounds only loosely (cos: 2^-11 absolute), so the spread there
 * is approximate. The moved range and point follow noise.c's double
 * arithmetic (float without float64). */
#ifndef RC_NOISE_GLSL
#define RC_NOISE_GLSL

/* ---- 64-bit words as uvec2 (x low, y high) ---------------------------------- */

uvec2 add64(uvec2 a, uvec2 b)
{
    uint carry;
    uint lo = uaddCarry(a.x, b.x, carry);
    return uvec2(lo, a.y + b.y + carry);
}

/* the low 64 bits of a * b */
uvec2 mul64(uvec2 a, uvec2 b)
{
    uint hi, lo;
    umulExtended(a.x, b.x, hi, lo);
    return uvec2(lo, hi + a.x * b.y + a.y * b.x);
}

/* a >> n, 0 < n < 32 */
uvec2 shr64(uvec2 a, uint n) { return uvec2((a.x >> n) | (a.y << (32u - n)), a.y >> n); }

const uvec2 GOLDEN64 = uvec2(0x7F4A7C15u, 0x9E3779B9u);

uvec2 mix64(uvec2 z)
{
    z ^= shr64(z, 30u);
    z = mul64(z, uvec2(0x1CE4E5B9u, 0xBF58476Du));
    z ^= shr64(z, 27u);
    z = mul64(z, uvec2(0x133111EBu, 0x94D049BBu));
    return z ^ shr64(z, 31u);
}

/* rc__noise_uniform's 53 bits, m in [0, 2^53): the uniform is (m + 1) / 2^53 */
uvec2 noise_bits(uvec2 key, uvec2 index)
{
    return shr64(mix64(add64(key, mul64(add64(index, uvec2(1u, 0u)), GOLDEN64))), 11u);
}

/* (float)((m + 1) / 2^53), rounded to nearest as the host's cast: the integer
 * is cut to 32 bits with the dropped bits ORed into bit 0 (below float's
 * rounding position, so the one rounding of uint -> float stays correct) */
float noise_uniform_f(uvec2 m)
{
    uvec2 v = add64(m, uvec2(1u, 0u));
    if (v.y == 0u) return float(v.x) * exp2(-53.0);
    int s = findMSB(v.y) + 1; /* bits to drop, 1..22 */
    uint kept = (v.x >> uint(s)) | (v.y << uint(32 - s));
    uint dropped = v.x & ((1u << uint(s)) - 1u);
    if (dropped != 0u) kept |= 1u;
    return float(kept) * exp2(float(s - 53));
}

#if RC_FP64
const double LN2_HI = 6.93147180369123816490e-01lf;
const double LN2_LO = 1.90821492927058770002e-10lf;

/* natural log of x > 0 in double: x = m 2^e, m in [sqrt(1/2), sqrt(2)),
 * log m = 2 atanh(s), s = (m - 1) / (m + 1), |s| < 0.172 */
double log_d(double x)
{
    int e;
    double m = frexp(x, e);
    if (m < 0.70710678118654752440lf) {
        m *= 2.0lf;
        e -= 1;
    }
    double s = (m - 1.0lf) / (m + 1.0lf), s2 = s * s, sum = 1.0lf / 23.0lf;
    for (int k = 21; k >= 1; k -= 2) sum = sum * s2 + 1.0lf / double(k);
    return double(e) * LN2_HI + (double(e) * LN2_LO + 2.0lf * s * sum);
}

/* e^x in double: x = k ln2 + t, |t| <= ln2 / 2, Taylor to t^18 */
double exp_d(double x)
{
    double k = floor(x / LN2_HI + 0.5lf);
    double t = (x - k * LN2_HI) - k * LN2_LO, sum = 1.0lf;
    for (int n = 18; n >= 1; --n) sum = 1.0lf + sum * t / double(n);
    return ldexp(sum, int(k));
}

/* cos x in double for 0 <= x <= 7: the nearest multiple of pi/2 taken off,
 * Taylor to the 20th power on what is left (|r| <= pi/4) */
double cos_d(double x)
{
    const double PIO2_HI = 1.57079632673412561417e+00lf, PIO2_LO = 6.07710050650619224932e-11lf;
    double k = floor(x / PIO2_HI + 0.5lf);
    double r = (x - k * PIO2_HI) - k * PIO2_LO, r2 = r * r;
    double c = 1.0lf, s = 1.0lf;
    for (int n = 20; n >= 2; n -= 2) c = 1.0lf - c * r2 / double(n * (n - 1));
    for (int n = 19; n >= 3; n -= 2) s = 1.0lf - s * r2 / double(n * (n - 1));
    s *= r;
    uint q = uint(k) & 3u;
    return q == 0u ? c : q == 1u ? -s : q == 2u ? -c : s;
}
#endif

/* rc__noise_normal: one Box-Muller output, in float, of indices index and
 * index + 1 */
float noise_normal(uvec2 key, uvec2 index)
{
    float u1 = noise_uniform_f(noise_bits(key, index));
    float u2 = noise_uniform_f(noise_bits(key, add64(index, uvec2(1u, 0u))));
    precise float angle = 6.2831853 * u2;
#if RC_FP64
    float l = float(log_d(double(u1)));
    precise float a = -2.0 * l;
    float root = float(sqrt(double(a)));
    float c = float(cos_d(double(angle)));
#else
    precise float a = -2.0 * log(u1);
    float root = sqrt(a);
    float c = cos(angle);
#endif
    precise float z = root * c;
    return z;
}

#endif
