/* The body of the x86 ray preparation in SIMD lanes, written once for both
 * widths: ray_batch.c includes it for four lanes (SSE2) and, where the CPU
 * has AVX2, for eight (AVX). No include guard: the includer defines
 * RC__RP_NAME (the function's name), RC__RP_ATTR (attributes beyond static
 * inline), RC__RP_W (lanes), the vector type RC__RP_T, the operations below
 * and RC__RP_STORE, and includes this file, which undefines them all at its
 * end.
 *
 *   SET1(x) ADD MUL DIV       IEEE single precision, no contraction
 *   AND OR ANDNOT(m, a)       ANDNOT is ~m & a
 *   GT LT(a, b)               ordered compares, a mask per lane
 *   INT(i)                    the integer i in every lane, as float bits
 *   DIRS(k)                   component k of the directions d[0 .. W)
 *   STORE(four, h, org, ...)  rays four .. four + 3 from half h of each vector
 *
 * Every lane repeats rc__ray_prepare's operations on rc__rot_apply_f's turn
 * in their order, with selects where it branches, so each ray gets its
 * values bit for bit (tests/test_ray_batch.c). */
static RC__FORCE_INLINE RC__RP_ATTR void RC__RP_NAME(const float r[9], const float org[3],
                                                     const float *const d[RC__RP_W], rc__ray *rays)
{
#define SEL(m, a, b) RC__RP_OR(RC__RP_AND(m, a), RC__RP_ANDNOT(m, b))
    const RC__RP_T one = RC__RP_SET1(1.0f), abs_mask = RC__RP_INT(0x7FFFFFFF);
    const RC__RP_T sx_ = RC__RP_DIRS(0), sy_ = RC__RP_DIRS(1), sz_ = RC__RP_DIRS(2);
    /* the turn, as rc__rot_apply_f: (r0 x + r1 y) + r2 z */
    const RC__RP_T wx = RC__RP_ADD(RC__RP_ADD(RC__RP_MUL(RC__RP_SET1(r[0]), sx_), RC__RP_MUL(RC__RP_SET1(r[1]), sy_)),
                                   RC__RP_MUL(RC__RP_SET1(r[2]), sz_));
    const RC__RP_T wy = RC__RP_ADD(RC__RP_ADD(RC__RP_MUL(RC__RP_SET1(r[3]), sx_), RC__RP_MUL(RC__RP_SET1(r[4]), sy_)),
                                   RC__RP_MUL(RC__RP_SET1(r[5]), sz_));
    const RC__RP_T wz = RC__RP_ADD(RC__RP_ADD(RC__RP_MUL(RC__RP_SET1(r[6]), sx_), RC__RP_MUL(RC__RP_SET1(r[7]), sy_)),
                                   RC__RP_MUL(RC__RP_SET1(r[8]), sz_));
    const RC__RP_T ix = RC__RP_DIV(one, wx), iy = RC__RP_DIV(one, wy), iz = RC__RP_DIV(one, wz);
    const RC__RP_T ax = RC__RP_AND(wx, abs_mask), ay = RC__RP_AND(wy, abs_mask), az = RC__RP_AND(wz, abs_mask);
    /* kz: the largest magnitude, the first on a tie (y beats x only when
     * larger, z beats the winner only when larger) */
    const RC__RP_T y_wins = RC__RP_GT(ay, ax);
    const RC__RP_T z_wins = RC__RP_GT(az, SEL(y_wins, ay, ax));
    const RC__RP_T y_only = RC__RP_ANDNOT(z_wins, y_wins);
    /* along kz: its component, its reciprocal; kx = kz + 1 and ky = kz + 2
     * (mod 3), swapped when the component along kz is negative */
    const RC__RP_T dz = SEL(z_wins, wz, SEL(y_only, wy, wx));
    const RC__RP_T rz = SEL(z_wins, iz, SEL(y_only, iy, ix));
    const RC__RP_T next = SEL(z_wins, wx, SEL(y_only, wz, wy));  /* component kz + 1 */
    const RC__RP_T after = SEL(z_wins, wy, SEL(y_only, wx, wz)); /* component kz + 2 */
    const RC__RP_T neg = RC__RP_LT(dz, RC__RP_SET1(0.0f));
    const RC__RP_T sx = RC__RP_DIV(SEL(neg, after, next), dz);
    const RC__RP_T sy = RC__RP_DIV(SEL(neg, next, after), dz);
    /* kz 0, 1, 2 by y_only and z_wins, and kx, ky: the per-ray path's
     * integers, as float bits */
    const RC__RP_T k0 = RC__RP_INT(0), k1 = RC__RP_INT(1), k2 = RC__RP_INT(2);
    const RC__RP_T kz = SEL(z_wins, k2, SEL(y_only, k1, k0));
    const RC__RP_T kx0 = SEL(z_wins, k0, SEL(y_only, k2, k1));
    const RC__RP_T ky0 = SEL(z_wins, k1, SEL(y_only, k0, k2));
    const RC__RP_T kx = SEL(neg, ky0, kx0), ky = SEL(neg, kx0, ky0);
    int h;
    for (h = 0; h < RC__RP_W / 4; ++h) RC__RP_STORE(rays + 4 * h, h, org, wx, wy, wz, ix, iy, iz, kx, ky, kz, sx, sy, rz);
#undef SEL
}

#undef RC__RP_NAME
#undef RC__RP_ATTR
#undef RC__RP_W
#undef RC__RP_T
#undef RC__RP_SET1
#undef RC__RP_ADD
#undef RC__RP_MUL
#undef RC__RP_DIV
#undef RC__RP_AND
#undef RC__RP_OR
#undef RC__RP_ANDNOT
#undef RC__RP_GT
#undef RC__RP_LT
#undef RC__RP_INT
#undef RC__RP_DIRS
#undef RC__RP_STORE
