/* The body of the leaf test in SIMD lanes, written once for every lane
 * width: leaf4.h includes it for four lanes (SSE2, NEON) and leaf4_avx2.c
 * for eight (two rays in AVX2). No include guard: each includer defines
 * RC__VL_NAME (the function's name), RC__VL_ATTR (its attributes beyond
 * static inline), the types RC__VL_T (floats) and RC__VL_M (lane masks), and
 * the operations below and includes this file, which undefines them all
 * at its end.
 *
 *   SET1(x) SUB ADD MUL DIV          IEEE single precision, no contraction
 *   LT GT EQ(a, b)                   ordered compares, a mask per lane
 *   ORDERED UNORDERED(a, b)          neither / either lane is a NaN
 *   OR AND(m, n)  ANDNOT(m, n)       ANDNOT is ~m & n
 *   ABS(a)  BITS(m)                  lane i's mask as bit i of a uint32_t
 *
 * With RC__VL_FILTER_ONLY (32-bit ARM, whose NEON flushes subnormals to zero
 * and has no division) only the sign test runs, and RC__VL_TINY(a) (|a| <
 * FLT_MIN) marks the lanes where the flush may have changed its answer; ADD,
 * DIV, EQ, ABS and UNORDERED are then not needed.
 *
 * Every lane repeats rc__tri_intersect's operations in its order, so its
 * edge functions and t are the scalar test's bit for bit. The
 * inputs are the three vertices' coordinates along the ray's kx, ky, kz, and
 * the ray's origin along them and shear constants, per lane; `all` has a bit
 * for each lane that holds a real triangle. The outputs are rc__leaf4_out's
 * (leaf4.h): *hit and *redo as bits, and t per lane (zero in every lane
 * when no lane survives the sign test; unset with RC__VL_FILTER_ONLY). No
 * result needs the barycentrics, so they are not computed. */
static RC__FORCE_INLINE RC__VL_ATTR void RC__VL_NAME(RC__VL_T ax, RC__VL_T ay, RC__VL_T az_, RC__VL_T bx, RC__VL_T by,
                                                     RC__VL_T bz_, RC__VL_T cx, RC__VL_T cy, RC__VL_T cz_, RC__VL_T ox,
                                                     RC__VL_T oy, RC__VL_T oz, RC__VL_T sx, RC__VL_T sy, RC__VL_T sz,
                                                     uint32_t all, uint32_t *hit, uint32_t *redo, RC__VL_T *t)
{
    const RC__VL_T zero = RC__VL_SET1(0.0f);
    const RC__VL_T az = RC__VL_SUB(az_, oz), bz = RC__VL_SUB(bz_, oz), cz = RC__VL_SUB(cz_, oz);
    const RC__VL_T Ax = RC__VL_SUB(RC__VL_SUB(ax, ox), RC__VL_MUL(sx, az));
    const RC__VL_T Ay = RC__VL_SUB(RC__VL_SUB(ay, oy), RC__VL_MUL(sy, az));
    const RC__VL_T Bx = RC__VL_SUB(RC__VL_SUB(bx, ox), RC__VL_MUL(sx, bz));
    const RC__VL_T By = RC__VL_SUB(RC__VL_SUB(by, oy), RC__VL_MUL(sy, bz));
    const RC__VL_T Cx = RC__VL_SUB(RC__VL_SUB(cx, ox), RC__VL_MUL(sx, cz));
    const RC__VL_T Cy = RC__VL_SUB(RC__VL_SUB(cy, oy), RC__VL_MUL(sy, cz));
    const RC__VL_T CxBy = RC__VL_MUL(Cx, By), CyBx = RC__VL_MUL(Cy, Bx);
    const RC__VL_T AxCy = RC__VL_MUL(Ax, Cy), AyCx = RC__VL_MUL(Ay, Cx);
    const RC__VL_T BxAy = RC__VL_MUL(Bx, Ay), ByAx = RC__VL_MUL(By, Ax);
    const RC__VL_T U = RC__VL_SUB(CxBy, CyBx), V = RC__VL_SUB(AxCy, AyCx), W = RC__VL_SUB(BxAy, ByAx);
    const RC__VL_M neg = RC__VL_OR(RC__VL_OR(RC__VL_LT(U, zero), RC__VL_LT(V, zero)), RC__VL_LT(W, zero));
    const RC__VL_M pos = RC__VL_OR(RC__VL_OR(RC__VL_GT(U, zero), RC__VL_GT(V, zero)), RC__VL_GT(W, zero));
    /* a lane with a NaN (overflow) goes to the scalar test, which orders its
     * comparisons its own way */
    const RC__VL_M ordered = RC__VL_AND(RC__VL_ORDERED(U, V), RC__VL_ORDERED(W, W));
    const RC__VL_M rejected = RC__VL_AND(RC__VL_AND(neg, pos), ordered);
#if !defined(RC__VL_FILTER_ONLY)
    /* the scalar test's order: a NaN or a zero edge function (equal
     * products) goes to double, then det == 0 and t <= 0 miss, then a t tiny
     * against the triangle's extent along the ray goes to double. The lanes'
     * conditions are combined as masks and read out as bits three times at
     * most (a read-out is five instructions on NEON). */
    const RC__VL_M redo_m = RC__VL_ANDNOT(
        rejected, RC__VL_OR(RC__VL_OR(RC__VL_UNORDERED(U, V), RC__VL_UNORDERED(W, W)),
                            RC__VL_OR(RC__VL_OR(RC__VL_EQ(CxBy, CyBx), RC__VL_EQ(AxCy, AyCx)), RC__VL_EQ(BxAy, ByAx))));
    const RC__VL_M settled = RC__VL_OR(rejected, redo_m);
    if (all & ~RC__VL_BITS(settled)) {
        const RC__VL_T det = RC__VL_ADD(RC__VL_ADD(U, V), W);
        const RC__VL_T T = RC__VL_ADD(RC__VL_ADD(RC__VL_MUL(U, RC__VL_MUL(sz, az)), RC__VL_MUL(V, RC__VL_MUL(sz, bz))),
                                      RC__VL_MUL(W, RC__VL_MUL(sz, cz)));
        const RC__VL_T tt = RC__VL_DIV(T, det);
        const RC__VL_M pass = RC__VL_ANDNOT(RC__VL_OR(settled, RC__VL_EQ(det, zero)), RC__VL_GT(tt, zero));
        const RC__VL_T extent = RC__VL_ADD(RC__VL_ADD(RC__VL_ABS(az), RC__VL_ABS(bz)), RC__VL_ABS(cz));
        const RC__VL_M tiny =
            RC__VL_AND(pass, RC__VL_LT(RC__VL_MUL(tt, RC__VL_SET1(1024.0f)), RC__VL_MUL(RC__VL_ABS(sz), extent)));
        *redo = all & RC__VL_BITS(RC__VL_OR(redo_m, tiny));
        *hit = all & RC__VL_BITS(RC__VL_ANDNOT(tiny, pass));
        *t = tt;
    } else {
        *redo = all & RC__VL_BITS(redo_m);
        *hit = 0;
        /* never read (no hit bit); set so no path reads them unset */
        *t = zero;
    }
#else
    /* A flushed value reads as zero where the scalar test (VFP) keeps it, so
     * a lane where any value of the test lies below FLT_MIN in magnitude is
     * left to the scalar test instead of being rejected (test_leaf4 found a
     * direction whose shear constant was subnormal, under qemu-arm). */
    {
#define RC__VL_TINY3(a, b, c) RC__VL_OR(RC__VL_OR(RC__VL_TINY(a), RC__VL_TINY(b)), RC__VL_TINY(c))
        const RC__VL_M inputs = RC__VL_OR(
            RC__VL_OR(RC__VL_TINY3(ax, ay, az_), RC__VL_TINY3(bx, by, bz_)),
            RC__VL_OR(RC__VL_TINY3(cx, cy, cz_), RC__VL_OR(RC__VL_TINY3(ox, oy, oz), RC__VL_TINY3(sx, sy, sy))));
        const RC__VL_M shear = RC__VL_OR(
            RC__VL_OR(RC__VL_TINY3(az, bz, cz),
                      RC__VL_TINY3(RC__VL_SUB(ax, ox), RC__VL_SUB(ay, oy), RC__VL_SUB(bx, ox))),
            RC__VL_OR(RC__VL_TINY3(RC__VL_SUB(by, oy), RC__VL_SUB(cx, ox), RC__VL_SUB(cy, oy)),
                      RC__VL_OR(RC__VL_TINY3(RC__VL_MUL(sx, az), RC__VL_MUL(sy, az), RC__VL_MUL(sx, bz)),
                                RC__VL_TINY3(RC__VL_MUL(sy, bz), RC__VL_MUL(sx, cz), RC__VL_MUL(sy, cz)))));
        const RC__VL_M edges =
            RC__VL_OR(RC__VL_OR(RC__VL_TINY3(Ax, Ay, Bx), RC__VL_TINY3(By, Cx, Cy)),
                      RC__VL_OR(RC__VL_TINY3(CxBy, CyBx, AxCy), RC__VL_TINY3(AyCx, BxAy, ByAx)));
#undef RC__VL_TINY3
        (void)sz;
        (void)t;
        *redo = all & ~RC__VL_BITS(RC__VL_ANDNOT(RC__VL_OR(inputs, RC__VL_OR(shear, edges)), rejected));
        *hit = 0;
    }
#endif
}

#undef RC__VL_NAME
#undef RC__VL_ATTR
#undef RC__VL_T
#undef RC__VL_M
#undef RC__VL_SET1
#undef RC__VL_SUB
#undef RC__VL_ADD
#undef RC__VL_MUL
#undef RC__VL_DIV
#undef RC__VL_LT
#undef RC__VL_GT
#undef RC__VL_EQ
#undef RC__VL_ORDERED
#undef RC__VL_UNORDERED
#undef RC__VL_OR
#undef RC__VL_AND
#undef RC__VL_ANDNOT
#undef RC__VL_ABS
#undef RC__VL_BITS
#undef RC__VL_FILTER_ONLY
#undef RC__VL_TINY
