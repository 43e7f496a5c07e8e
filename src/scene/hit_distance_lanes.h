/* The body of the float64 refinement of several hits at once (scene_trace.c),
 * written once for both widths: two hits in SSE2 doubles, and four in AVX
 * doubles where the CPU has AVX2. No include guard: the includer defines
 * RC__HD_NAME (the function's name), RC__HD_ATTR (attributes beyond static
 * inline), RC__HD_W (hits), the vector type RC__HD_T, the operations below,
 * and includes this file, which undefines them all at its end.
 *
 *   SET1(x) ADD SUB MUL DIV    IEEE double precision, no contraction
 *   GATHER(p, k)               coordinate k of p[0 .. W), widened, one a lane
 *   ODD(dn, q)                 bit i: lane i's dn is zero or q is not finite
 *   FAR(q, t, c)               bit i: |q - t| > c * t in lane i (q finite)
 *   HIT_T(hits, at)            hits[at[i]].t, widened, one a lane
 *   STORE(p, v)                the lanes of v to p[0 .. W)
 *
 * It defines RC__HD_NAME (corners and directions by pointer), and
 * RC__HD_NAME_corners and RC__HD_NAME_tail for callers that have the
 * coordinates in lanes already (scene_trace.c's rows).
 *
 * Lane i repeats rc__scene_hit_distance_d's operations in their order for a
 * hit on the triangle a[i], b[i], c[i] (own mesh) along the sensor direction
 * dir[i] (hits[at[i]]), so each value is that function's bit for bit
 * (tests/test_simulate_paths.c); td[at[i]] gets it, or the traversal's
 * distance where that function keeps it. A quotient further from the
 * traversal's t than RC__REFINE_NEAR allows is not decided here: the
 * functions return those lanes as bits, and the caller gives each hit to
 * rc__scene_hit_distance_d, which checks it against the triangle's corners
 * (rays along the triangle's plane; no ordinary hit comes near this). */
#define RC__HD_CAT2(a, b) a##b
#define RC__HD_CAT(a, b) RC__HD_CAT2(a, b)

/* The rest once the direction (px, py, pz, sensor frame), the first corner
 * (ax, ay, az) and the normal (nx, ny, nz) are in lanes */
static RC__FORCE_INLINE RC__HD_ATTR int RC__HD_CAT(RC__HD_NAME, _tail)(RC__HD_T px, RC__HD_T py, RC__HD_T pz,
                                                                      RC__HD_T ax, RC__HD_T ay, RC__HD_T az,
                                                                      RC__HD_T nx, RC__HD_T ny, RC__HD_T nz,
                                                                      const rc__xformf *world, const rc__hit *hits,
                                                                      const uint32_t *at, double *td)
{
    const double *r = world->rd;
    /* the sensor direction turned into the scene frame, as rot_d */
    const RC__HD_T dx = RC__HD_ADD(RC__HD_ADD(RC__HD_MUL(RC__HD_SET1(r[0]), px), RC__HD_MUL(RC__HD_SET1(r[1]), py)),
                                   RC__HD_MUL(RC__HD_SET1(r[2]), pz));
    const RC__HD_T dy = RC__HD_ADD(RC__HD_ADD(RC__HD_MUL(RC__HD_SET1(r[3]), px), RC__HD_MUL(RC__HD_SET1(r[4]), py)),
                                   RC__HD_MUL(RC__HD_SET1(r[5]), pz));
    const RC__HD_T dz = RC__HD_ADD(RC__HD_ADD(RC__HD_MUL(RC__HD_SET1(r[6]), px), RC__HD_MUL(RC__HD_SET1(r[7]), py)),
                                   RC__HD_MUL(RC__HD_SET1(r[8]), pz));
    const RC__HD_T dn = RC__HD_ADD(RC__HD_ADD(RC__HD_MUL(nx, dx), RC__HD_MUL(ny, dy)), RC__HD_MUL(nz, dz));
    const RC__HD_T w = RC__HD_ADD(RC__HD_ADD(RC__HD_MUL(nx, RC__HD_SUB(ax, RC__HD_SET1(world->td[0]))),
                                             RC__HD_MUL(ny, RC__HD_SUB(ay, RC__HD_SET1(world->td[1])))),
                                  RC__HD_MUL(nz, RC__HD_SUB(az, RC__HD_SET1(world->td[2]))));
    const RC__HD_T quot = RC__HD_DIV(w, dn);
    const int odd = RC__HD_ODD(dn, quot);
    double q[RC__HD_W];
    int i;
    RC__HD_STORE(q, quot);
    for (i = 0; i < RC__HD_W; ++i) td[at[i]] = (odd >> i) & 1 ? (double)hits[at[i]].t : q[i];
    return RC__HD_FAR(quot, RC__HD_HIT_T(hits, at), RC__REFINE_NEAR) & ~odd;
}

/* ... from the three corners in lanes: the normal of the edges from a */
static RC__FORCE_INLINE RC__HD_ATTR int RC__HD_CAT(RC__HD_NAME, _corners)(
    RC__HD_T px, RC__HD_T py, RC__HD_T pz, RC__HD_T ax, RC__HD_T ay, RC__HD_T az, RC__HD_T bx, RC__HD_T by,
    RC__HD_T bz, RC__HD_T cx, RC__HD_T cy, RC__HD_T cz, const rc__xformf *world, const rc__hit *hits,
    const uint32_t *at, double *td)
{
    const RC__HD_T e1x = RC__HD_SUB(bx, ax), e1y = RC__HD_SUB(by, ay), e1z = RC__HD_SUB(bz, az);
    const RC__HD_T e2x = RC__HD_SUB(cx, ax), e2y = RC__HD_SUB(cy, ay), e2z = RC__HD_SUB(cz, az);
    return RC__HD_CAT(RC__HD_NAME, _tail)(
        px, py, pz, ax, ay, az, RC__HD_SUB(RC__HD_MUL(e1y, e2z), RC__HD_MUL(e1z, e2y)),
     RC__HD_SUB(RC__HD_MUL(e1z, e2x), RC__HD_MUL(e1x, e2z)), RC__HD_SUB(RC__HD_MUL(e1x, e2y), RC__HD_MUL(e1y, e2x)),
     world, hits, at, td);
}

static RC__FORCE_INLINE RC__HD_ATTR int RC__HD_NAME(const float *const a[RC__HD_W], const float *const b[RC__HD_W],
                                                     const float *const c[RC__HD_W], const float *const dir[RC__HD_W],
                                                     const rc__xformf *world, const rc__hit *hits,
                                                     const uint32_t *at, double *td)
{
    const RC__HD_T px = RC__HD_GATHER(dir, 0), py = RC__HD_GATHER(dir, 1), pz = RC__HD_GATHER(dir, 2);
    int same = 1, i;
    for (i = 1; i < RC__HD_W; ++i) same &= a[i] == a[0] && b[i] == b[0] && c[i] == c[0];
    if (same) {
        /* one triangle for every lane (most groups on a small map): its
         * normal once, by the same operations in scalar doubles, so the
         * same values */
        const double sax = a[0][0], say = a[0][1], saz = a[0][2];
        const double e1x = b[0][0] - sax, e1y = b[0][1] - say, e1z = b[0][2] - saz;
        const double e2x = c[0][0] - sax, e2y = c[0][1] - say, e2z = c[0][2] - saz;
        return RC__HD_CAT(RC__HD_NAME, _tail)(
            px, py, pz, RC__HD_SET1(sax), RC__HD_SET1(say), RC__HD_SET1(saz), RC__HD_SET1(e1y * e2z - e1z * e2y),
            RC__HD_SET1(e1z * e2x - e1x * e2z), RC__HD_SET1(e1x * e2y - e1y * e2x), world, hits, at, td);
    }
    return RC__HD_CAT(RC__HD_NAME, _corners)(
        px, py, pz, RC__HD_GATHER(a, 0), RC__HD_GATHER(a, 1), RC__HD_GATHER(a, 2), RC__HD_GATHER(b, 0),
     RC__HD_GATHER(b, 1), RC__HD_GATHER(b, 2), RC__HD_GATHER(c, 0), RC__HD_GATHER(c, 1), RC__HD_GATHER(c, 2), world,
     hits, at, td);
}

#undef RC__HD_CAT
#undef RC__HD_CAT2
#undef RC__HD_NAME
#undef RC__HD_ATTR
#undef RC__HD_W
#undef RC__HD_T
#undef RC__HD_SET1
#undef RC__HD_ADD
#undef RC__HD_SUB
#undef RC__HD_MUL
#undef RC__HD_DIV
#undef RC__HD_GATHER
#undef RC__HD_ODD
#undef RC__HD_FAR
#undef RC__HD_HIT_T
#undef RC__HD_STORE
