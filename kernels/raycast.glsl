/* rangecast: the body of the ray casting kernel, included by raycast.comp
 * (GLSL 450, the BVH walk) and raycast_rq.comp (GLSL 460 with
 * GL_EXT_ray_query); see raycast.comp for what it does. */
#include "layout.glsl"

#ifndef RC_FP64
#define RC_FP64 1
#endif
#ifndef RC_CHUNKS
#define RC_CHUNKS 4
#endif
#ifndef RC_RAY_QUERY
#define RC_RAY_QUERY 0
#endif

#define MAX_DEPTH 64u /* RC__BVH_MAX_DEPTH */

layout(local_size_x_id = 0) in;
layout(constant_id = 1) const uint ATTRS = 0x7Fu;
layout(constant_id = 2) const uint MODEL = 0u;
/* log2 of the elements one binding holds (chunked arrays) */
layout(constant_id = 3) const uint NODE_SHIFT = 31u;
layout(constant_id = 4) const uint TRI_SHIFT = 31u;
layout(constant_id = 5) const uint VERT_SHIFT = 31u;

layout(std430, binding = 4) readonly buffer Tris0 { uint t[]; } tris0;
layout(std430, binding = 8) readonly buffer Verts0 { float v[]; } verts0;
#if RC_CHUNKS > 1
layout(std430, binding = 5) readonly buffer Tris1 { uint t[]; } tris1;
layout(std430, binding = 6) readonly buffer Tris2 { uint t[]; } tris2;
layout(std430, binding = 7) readonly buffer Tris3 { uint t[]; } tris3;
layout(std430, binding = 9) readonly buffer Verts1 { float v[]; } verts1;
layout(std430, binding = 10) readonly buffer Verts2 { float v[]; } verts2;
layout(std430, binding = 11) readonly buffer Verts3 { float v[]; } verts3;
#endif
/* The node bindings as 16-byte words: a mesh's wide nodes (WNode, 8 words)
 * and the top level's Nodes (2 words) */
layout(std430, binding = 0) readonly buffer NodeWords0 { uvec4 q[]; } words0;
#if RC_CHUNKS > 1
layout(std430, binding = 1) readonly buffer NodeWords1 { uvec4 q[]; } words1;
layout(std430, binding = 2) readonly buffer NodeWords2 { uvec4 q[]; } words2;
layout(std430, binding = 3) readonly buffer NodeWords3 { uvec4 q[]; } words3;
#endif
layout(std430, binding = 12) readonly buffer Refs { uint r[]; } refs;
layout(std430, binding = 13) readonly buffer Geoms { Geom g[]; } geoms;
layout(std430, binding = 14) readonly buffer Insts { Inst i[]; } insts;
layout(std430, binding = 15) readonly buffer Xforms { uvec4 x[]; } xforms;
layout(std430, binding = 16) readonly buffer Rays { uint r[]; } rays;
layout(std430, binding = 17) writeonly buffer Out { uint o[]; } outb;
#if RC_RAY_QUERY
layout(binding = 18) uniform accelerationStructureEXT tlas;
#endif

layout(push_constant) uniform PC {
    uint first_pose;  /* pose of element 0 of this dispatch */
    uint first_ray;   /* ray (within its scan) of element 0 */
    uint count;       /* elements in this dispatch */
    uint rays;        /* rays per scan */
    uint columns;     /* grid columns */
    uint grid_rows;   /* grid rows */
    float range_min;
    float range_max;
    uint geom_count;  /* the scene's own geometries: top items below this */
    uint top_node;    /* node index of the top-level root */
    uint top_ref;     /* ref index of the top level's refs */
    uint groups_x;    /* workgroups per row of the 2D dispatch */
    uint flags;       /* bit 0: one mesh, no instances: skip the top level; bit 31 never set (f32) */
    uint off_hits, off_ranges, off_points, off_normals, off_prim, off_geom, off_inst;
    /* range noise of results kept on the device (noise.glsl) */
    uint noise_key_lo, noise_key_hi;   /* rc__noise_key(seed, draw) */
    uint noise_drop_lo, noise_drop_hi; /* dropout when the 53 uniform bits are below this */
    float noise_mean, noise_sigma, noise_exponent;
    uint noise_flags;                  /* NOISE_* */
} pc;

#define NOISE_ON 1u
#define NOISE_MOVES 2u
#define NOISE_DROPS 4u
#define RC_FLAGS_NEVER_SET 0x80000000u /* RC__VK_FLAGS_NEVER_SET */
#define RC_FLAGS_SKEW_DIV 0x40000000u  /* RC__VK_FLAGS_SKEW_DIV: tests only */
#define RC_FLAGS_SKIP_WALK 0x20000000u  /* RC__VK_FLAGS_SKIP_WALK: measurements only */
#define RC_FLAGS_SKIP_REFINE 0x10000000u /* RC__VK_FLAGS_SKIP_REFINE: measurements only */

/* ---- chunked loads ------------------------------------------------------ */

/* Word w of the node arrays (two per Node slot). */
uvec4 load_word(uint w)
{
#if RC_CHUNKS > 1
    uint c = (w >> 1u) >> NODE_SHIFT, j = w - ((c << NODE_SHIFT) << 1u);
    if (c == 0u) return words0.q[j];
    if (c == 1u) return words1.q[j];
    if (c == 2u) return words2.q[j];
    return words3.q[j];
#else
    return words0.q[w];
#endif
}

/* Node slot i (the top level's binary nodes). */
Node load_node(uint i)
{
    uvec4 a = load_word(2u * i), b = load_word(2u * i + 1u);
    Node n;
    n.bmin = uintBitsToFloat(a.xyz);
    n.index = a.w;
    n.bmax = uintBitsToFloat(b.xyz);
    n.count = b.w;
    return n;
}

uvec3 load_tri(uint p)
{
#if RC_CHUNKS > 1
    uint c = p >> TRI_SHIFT, j = (p & ((1u << TRI_SHIFT) - 1u)) * 3u;
    if (c == 0u) return uvec3(tris0.t[j], tris0.t[j + 1u], tris0.t[j + 2u]);
    if (c == 1u) return uvec3(tris1.t[j], tris1.t[j + 1u], tris1.t[j + 2u]);
    if (c == 2u) return uvec3(tris2.t[j], tris2.t[j + 1u], tris2.t[j + 2u]);
    return uvec3(tris3.t[j], tris3.t[j + 1u], tris3.t[j + 2u]);
#else
    uint j = p * 3u;
    return uvec3(tris0.t[j], tris0.t[j + 1u], tris0.t[j + 2u]);
#endif
}

vec3 load_vertex(uint i)
{
#if RC_CHUNKS > 1
    uint c = i >> VERT_SHIFT, j = (i & ((1u << VERT_SHIFT) - 1u)) * 3u;
    if (c == 0u) return vec3(verts0.v[j], verts0.v[j + 1u], verts0.v[j + 2u]);
    if (c == 1u) return vec3(verts1.v[j], verts1.v[j + 1u], verts1.v[j + 2u]);
    if (c == 2u) return vec3(verts2.v[j], verts2.v[j + 1u], verts2.v[j + 2u]);
    return vec3(verts3.v[j], verts3.v[j + 1u], verts3.v[j + 2u]);
#else
    uint j = i * 3u;
    return vec3(verts0.v[j], verts0.v[j + 1u], verts0.v[j + 2u]);
#endif
}

/* ---- correctly rounded float division ------------------------------------ */

/* a / b rounded to nearest, as the CPU divides. A shader's float division may
 * be off by up to 2.5 ulps (Vulkan's bound for OpFDiv): on an H100 rays along
 * a box's diagonal slipped past the corner they touch (test_stability,
 * axis_parallel, 2 of 234), and with this function they no longer do; the
 * same loss shows on lavapipe when its divisions are skewed by 2 ulps
 * (RANGECAST_VULKAN_SKEW_DIV). The rounded quotient is the candidate with the smallest
 * remainder |a - q b|, so the driver's quotient is moved an ulp at a time while
 * a neighbour's remainder is smaller. With float64 each remainder is exact (a
 * float product has 48 bits); without it, a - (p + e) from Dekker's exact
 * product. Zero, subnormal, infinite and NaN quotients are left as they are. */
#if RC_FP64
#define REMAINDER double
double remainder_of(float a, float b, float q)
{
    precise double r = double(a) - double(q) * double(b);
    return abs(r);
}
#else
/* a * b = p + e exactly (Dekker's product with Veltkamp's split; no FMA). */
void two_prod(float a, float b, out float p, out float e)
{
    precise float pp = a * b;
    precise float ca = 4097.0 * a;
    precise float ahi = ca - (ca - a);
    precise float alo = a - ahi;
    precise float cb = 4097.0 * b;
    precise float bhi = cb - (cb - b);
    precise float blo = b - bhi;
    precise float ee = ((ahi * bhi - pp) + ahi * blo + alo * bhi) + alo * blo;
    p = pp;
    e = ee;
}

#define REMAINDER float
float remainder_of(float a, float b, float q)
{
    float p, e;
    two_prod(q, b, p, e);
    precise float r = (a - p) - e;
    return abs(r);
}
#endif

float div_rn(float a, float b)
{
    precise float q = a / b;
    if (!(abs(q) >= 1.17549435e-38) || isinf(q)) return q;
    uint u = floatBitsToUint(q);
    if ((pc.flags & RC_FLAGS_SKEW_DIV) != 0u) u += 2u; /* a driver's error, for the tests */
    int step_ = 0;
    for (int i = 0; i < 4; ++i) {
        /* bits u - 1 and u + 1 are the neighbours of smaller and larger magnitude */
        float lo = uintBitsToFloat(u - 1u), hi = uintBitsToFloat(u + 1u);
        float here = uintBitsToFloat(u);
        REMAINDER rq = remainder_of(a, b, here);
        if (step_ <= 0 && remainder_of(a, b, lo) < rq) {
            u -= 1u;
            step_ = -1;
        } else if (step_ >= 0 && remainder_of(a, b, hi) < rq) {
            u += 1u;
            step_ = 1;
        } else {
            break;
        }
    }
    return uintBitsToFloat(u);
}

/* ---- rays ----------------------------------------------------------------- */

struct Ray {
    vec3 org;
    vec3 dir;
    uint kx, ky, kz;
    float ox, oy, oz; /* org[kx], org[ky], org[kz] */
    float sx, sy, sz;
};

/* The slack of box tests and of dropping stacked boxes: 1 + 32 ulps, as the
 * CPU's RC__SLAB_FAR_SCALE (src/bvh/intersect.h): it covers the slab test's
 * rounding and the triangle test's, so a tie between meshes or instances is
 * never culled by a box whose entry rounds just above the hit. */
const float SLAB_FAR_SCALE = 1.0000038;

/* Slab-test constants: reciprocal direction, which plane is entered first,
 * and the axes the ray is parallel to. */
struct Slab {
    vec3 org;
    vec3 inv;
    bvec3 neg;
    bvec3 zero;
    bool any_zero;
};

/* rc__ray_prepare */
Ray make_ray(vec3 org, vec3 dir)
{
    Ray r;
    float ax = abs(dir.x), ay = abs(dir.y), az = abs(dir.z), m = ax;
    uint kz = 0u;
    if (ay > m) {
        kz = 1u;
        m = ay;
    }
    if (az > m) kz = 2u;
    r.org = org;
    r.dir = dir;
    r.kz = kz;
    r.kx = kz == 2u ? 0u : kz + 1u;
    r.ky = r.kx == 2u ? 0u : r.kx + 1u;
    if (dir[kz] < 0.0) {
        uint t = r.kx;
        r.kx = r.ky;
        r.ky = t;
    }
    r.ox = org[r.kx];
    r.oy = org[r.ky];
    r.oz = org[r.kz];
    r.sx = div_rn(dir[r.kx], dir[kz]);
    r.sy = div_rn(dir[r.ky], dir[kz]);
    r.sz = div_rn(1.0, dir[kz]);
    return r;
}

Slab make_slab(Ray r)
{
    Slab s;
    s.org = r.org;
    s.zero = equal(r.dir, vec3(0.0));
    /* 1/0 is never evaluated: parallel axes are decided by the inside test */
    vec3 d = mix(r.dir, vec3(1.0), s.zero);
    s.inv = vec3(div_rn(1.0, d.x), div_rn(1.0, d.y), div_rn(1.0, d.z));
    /* CPU: the entry plane is bmax where 1/dir < 0, including dir = -0.0 */
    s.neg = lessThan(r.dir, vec3(0.0));
    s.any_zero = any(s.zero);
    return s;
}

/* Conservative slab test (see the header): 1 when the box may meet the ray
 * within [0, tmax]; tnear = entry distance. */
bool node_hit(Node n, Slab s, float tmax, out float tnear)
{
    vec3 pn = mix(n.bmin, n.bmax, s.neg);
    vec3 pf = mix(n.bmax, n.bmin, s.neg);
    vec3 a = (pn - s.org) * s.inv;
    vec3 b = (pf - s.org) * s.inv;
    if (s.any_zero) {
        bvec3 outside = bvec3(s.org.x < n.bmin.x || s.org.x > n.bmax.x, s.org.y < n.bmin.y || s.org.y > n.bmax.y,
                              s.org.z < n.bmin.z || s.org.z > n.bmax.z);
        if ((s.zero.x && outside.x) || (s.zero.y && outside.y) || (s.zero.z && outside.z)) {
            tnear = 0.0;
            return false;
        }
        a = mix(a, vec3(0.0), s.zero);
        b = mix(b, vec3(tmax), s.zero);
    }
    float tn = max(max(a.x, a.y), max(a.z, 0.0));
    float tf = min(min(b.x, b.y), min(b.z, tmax));
    tnear = tn;
    return tn <= tf * SLAB_FAR_SCALE;
}

/* ---- watertight triangle test (rc__tri_intersect) ------------------------- */

#if RC_FP64
void edges_exact(float Ax, float Ay, float Bx, float By, float Cx, float Cy, out float U, out float V, out float W)
{
    precise double CxBy = double(Cx) * double(By);
    precise double CyBx = double(Cy) * double(Bx);
    precise double AxCy = double(Ax) * double(Cy);
    precise double AyCx = double(Ay) * double(Cx);
    precise double BxAy = double(Bx) * double(Ay);
    precise double ByAx = double(By) * double(Ax);
    precise double u = CxBy - CyBx;
    precise double v = AxCy - AyCx;
    precise double w = BxAy - ByAx;
    /* rc__clamp_to_float: no overflow to inf for huge coordinates */
    const double fmax = 3.4028234663852886e38lf;
    U = float(clamp(u, -fmax, fmax));
    V = float(clamp(v, -fmax, fmax));
    W = float(clamp(w, -fmax, fmax));
}

#else
/* a*b - c*d in float-float, rounded once more to float: the sign is exact
 * (outside contrived cancellations) and f(c, d, a, b) == -f(a, b, c, d)
 * exactly, which is what watertightness needs. */
float diff_of_products(float a, float b, float c, float d)
{
    float p1, e1, p2, e2;
    two_prod(a, b, p1, e1);
    two_prod(c, d, p2, e2);
    precise float s = p1 - p2;
    precise float bb = s - p1;
    precise float es = (p1 - (s - bb)) + (-p2 - bb);
    precise float r = s + (es + (e1 - e2));
    return r;
}

void edges_exact(float Ax, float Ay, float Bx, float By, float Cx, float Cy, out float U, out float V, out float W)
{
    U = diff_of_products(Cx, By, Cy, Bx);
    V = diff_of_products(Ax, Cy, Ay, Cx);
    W = diff_of_products(Bx, Ay, By, Ax);
}

#endif

#if RC_FP64
/* rc__tri_plane_t_double: distance along the ray to the plane of (a, b, c) in
 * double; false when it is not positive or not finite. */
bool tri_plane_t(Ray r, vec3 a, vec3 b, vec3 c, inout float t)
{
    precise double e1x = double(b.x) - double(a.x);
    precise double e1y = double(b.y) - double(a.y);
    precise double e1z = double(b.z) - double(a.z);
    precise double e2x = double(c.x) - double(a.x);
    precise double e2y = double(c.y) - double(a.y);
    precise double e2z = double(c.z) - double(a.z);
    precise double nx = e1y * e2z - e1z * e2y;
    precise double ny = e1z * e2x - e1x * e2z;
    precise double nz = e1x * e2y - e1y * e2x;
    precise double w = nx * (double(a.x) - double(r.org.x)) + ny * (double(a.y) - double(r.org.y)) +
                       nz * (double(a.z) - double(r.org.z));
    precise double dn = nx * double(r.dir.x) + ny * double(r.dir.y) + nz * double(r.dir.z);
    if (dn == 0.0lf) return false;
    precise double td = w / dn;
    if (!(td > 0.0lf) || !(td < 3.0e38lf)) return false;
    t = float(td);
    return t > 0.0;
}
#else
/* Without float64: the same plane distance in float (coarser: a self-hit is
 * rejected when the float distance is not positive). */
bool tri_plane_t(Ray r, vec3 a, vec3 b, vec3 c, inout float t)
{
    precise vec3 e1 = b - a;
    precise vec3 e2 = c - a;
    precise float nx = e1.y * e2.z - e1.z * e2.y;
    precise float ny = e1.z * e2.x - e1.x * e2.z;
    precise float nz = e1.x * e2.y - e1.y * e2.x;
    precise float w = nx * (a.x - r.org.x) + ny * (a.y - r.org.y) + nz * (a.z - r.org.z);
    precise float dn = nx * r.dir.x + ny * r.dir.y + nz * r.dir.z;
    if (dn == 0.0) return false;
    precise float td = div_rn(w, dn);
    if (!(td > 0.0) || !(td < 3.0e38)) return false;
    t = td;
    return true;
}
#endif

bool tri_intersect(Ray r, vec3 a, vec3 b, vec3 c, out float t)
{
    precise float az = a[r.kz] - r.oz;
    precise float bz = b[r.kz] - r.oz;
    precise float cz = c[r.kz] - r.oz;
    precise float Ax = (a[r.kx] - r.ox) - r.sx * az;
    precise float Ay = (a[r.ky] - r.oy) - r.sy * az;
    precise float Bx = (b[r.kx] - r.ox) - r.sx * bz;
    precise float By = (b[r.ky] - r.oy) - r.sy * bz;
    precise float Cx = (c[r.kx] - r.ox) - r.sx * cz;
    precise float Cy = (c[r.ky] - r.oy) - r.sy * cz;
    precise float CxBy = Cx * By;
    precise float CyBx = Cy * Bx;
    precise float AxCy = Ax * Cy;
    precise float AyCx = Ay * Cx;
    precise float BxAy = Bx * Ay;
    precise float ByAx = By * Ax;
    precise float U = CxBy - CyBx;
    precise float V = AxCy - AyCx;
    precise float W = BxAy - ByAx;
    t = 0.0;
    /* a non-zero float edge function has the exact one's sign (rounding is
     * monotonic): mixed non-zero signs reject before any exact recomputation */
    float lo = U < V ? (U < W ? U : W) : (V < W ? V : W);
    float hi = U > V ? (U > W ? U : W) : (V > W ? V : W);
    if (lo < 0.0 && hi > 0.0) return false;
    /* an edge function is exactly 0 when its two products are equal (also
     * where a device flushes a tiny difference to 0) */
    if (CxBy == CyBx || AxCy == AyCx || BxAy == ByAx) {
        edges_exact(Ax, Ay, Bx, By, Cx, Cy, U, V, W);
        if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return false;
    }
    precise float det = U + V + W;
    if (det == 0.0) return false;
    precise float T = U * (r.sz * az) + V * (r.sz * bz) + W * (r.sz * cz);
    float tt = div_rn(T, det);
    if (!(tt > 0.0)) return false;
    /* t tiny against the triangle's extent along the ray: the origin lies
     * (nearly) in its plane, where rounding can fake a small positive t;
     * decided against the plane instead (rc__tri_plane_t_double) */
    precise float extent = abs(r.sz) * (abs(az) + abs(bz) + abs(cz));
    if (tt * 1024.0 < extent && !tri_plane_t(r, a, b, c, tt)) return false;
    /* rc__tri_zero_area: decided on the host at upload (vulkan_pack.c writes
     * zero-area triangles as (a, a, a), which never pass det != 0) */
    t = tt;
    return true;
}

/* ---- traversal -------------------------------------------------------------- */

struct Hit {
    float t;
    uint prim, geom, inst;
    uint slot; /* the hit triangle's entry in tris (for the normal and the refinement) */
};

bool key_less(uint inst, uint geom, uint prim, Hit h)
{
    if (inst != h.inst) return inst < h.inst;
    if (geom != h.geom) return geom < h.geom;
    return prim < h.prim;
}

/* Lanes of a bvec4 as bits 0..3. */
uint bits4(bvec4 b) { return (b.x ? 1u : 0u) | (b.y ? 2u : 0u) | (b.z ? 4u : 0u) | (b.w ? 8u : 0u); }

/* Entry distances of a wide node's four child boxes (word w0 on), the
 * node's child and count words, and a mask of the children met within
 * [0, tmax]: node_hit for four boxes at once, empty slots never met. */
uint wide_box_test(uint w0, Slab s, float tmax, out vec4 tn, out uvec4 child, out uvec4 count)
{
    vec4 xl = uintBitsToFloat(load_word(w0)), xh = uintBitsToFloat(load_word(w0 + 1u));
    vec4 yl = uintBitsToFloat(load_word(w0 + 2u)), yh = uintBitsToFloat(load_word(w0 + 3u));
    vec4 zl = uintBitsToFloat(load_word(w0 + 4u)), zh = uintBitsToFloat(load_word(w0 + 5u));
    child = load_word(w0 + 6u);
    count = load_word(w0 + 7u);
    vec4 ax = ((s.neg.x ? xh : xl) - s.org.x) * s.inv.x;
    vec4 bx = ((s.neg.x ? xl : xh) - s.org.x) * s.inv.x;
    vec4 ay = ((s.neg.y ? yh : yl) - s.org.y) * s.inv.y;
    vec4 by = ((s.neg.y ? yl : yh) - s.org.y) * s.inv.y;
    vec4 az = ((s.neg.z ? zh : zl) - s.org.z) * s.inv.z;
    vec4 bz = ((s.neg.z ? zl : zh) - s.org.z) * s.inv.z;
    uint met = bits4(notEqual(child, uvec4(0xFFFFFFFFu)));
    if (s.any_zero) {
        /* an axis the ray is parallel to: inside its slab or never */
        if (s.zero.x) {
            met &= ~(bits4(lessThan(vec4(s.org.x), xl)) | bits4(greaterThan(vec4(s.org.x), xh)));
            ax = vec4(0.0);
            bx = vec4(tmax);
        }
        if (s.zero.y) {
            met &= ~(bits4(lessThan(vec4(s.org.y), yl)) | bits4(greaterThan(vec4(s.org.y), yh)));
            ay = vec4(0.0);
            by = vec4(tmax);
        }
        if (s.zero.z) {
            met &= ~(bits4(lessThan(vec4(s.org.z), zl)) | bits4(greaterThan(vec4(s.org.z), zh)));
            az = vec4(0.0);
            bz = vec4(tmax);
        }
    }
    tn = max(max(ax, ay), max(az, vec4(0.0)));
    vec4 tf = min(min(bx, by), min(bz, vec4(tmax)));
    return met & bits4(lessThanEqual(tn, tf * SLAB_FAR_SCALE));
}

/* Lane k of a vector by selects (a run-time index could go to local memory). */
float lane_f(vec4 v, uint k) { return k == 0u ? v.x : (k == 1u ? v.y : (k == 2u ? v.z : v.w)); }
uint lane_u(uvec4 v, uint k) { return k == 0u ? v.x : (k == 1u ? v.y : (k == 2u ? v.z : v.w)); }

#define WIDE_STACK (3u * MAX_DEPTH + 4u) /* three pushes per level at most */

/* rc__mesh_intersect over the mesh's 4-wide nodes (the CPU's own layout,
 * src/bvh/wide_trace.c), written "while-while" (Aila & Laine 2009): an inner
 * loop walks nodes only, a leaf's triangles are tested after it, so lanes of
 * a SIMD group test triangles together (and a masked-execution device such
 * as lavapipe runs each part only while some lane needs it). The nearest
 * child met is visited first, the others pushed with their entry distances,
 * popped entries dropped when they start beyond the nearest hit by more than
 * the box test's slack: the hit kept is the C code's whatever the order (the
 * tie rule decides equal distances). A stack entry is a node (count 0) or a
 * leaf's run of slots. */
bool trace_mesh(Ray r, Slab s, uint gi, uint geom_id, uint inst, inout Hit h)
{
    Geom g = geoms.g[gi];
    uint stk_c[WIDE_STACK];
    uint stk_n[WIDE_STACK];
    float stk_t[WIDE_STACK];
    uint sp = 0u, cur = 0u, cnt = 0u; /* the root node */
    bool found = false, alive = true;
    uint wbase = 2u * g.node_base;
    while (alive) {
        while (alive && cnt == 0u) {
            vec4 tn;
            uvec4 child, count;
            uint met = wide_box_test(wbase + 8u * cur, s, h.t, tn, child, count);
            if (met != 0u && (met & (met - 1u)) == 0u) { /* one child met: no order, no push */
                uint l = uint(findLSB(met));
                cur = lane_u(child, l);
                cnt = lane_u(count, l);
                continue;
            }
            if (met != 0u) {
                /* two to four met: the nearest visited, the others pushed in
                 * lane order. Sorting them farthest first, as the CPU does,
                 * measured slower on an H200 (1M: 114k against 122k scans/s;
                 * 1k: 250k against 263k): the pops' order matters less there
                 * than the sorting's instructions. */
                float best = 3.4028235e38;
                uint bl = uint(findLSB(met));
                if ((met & 1u) != 0u && tn.x < best) { best = tn.x; bl = 0u; }
                if ((met & 2u) != 0u && tn.y < best) { best = tn.y; bl = 1u; }
                if ((met & 4u) != 0u && tn.z < best) { best = tn.z; bl = 2u; }
                if ((met & 8u) != 0u && tn.w < best) { best = tn.w; bl = 3u; }
                met &= ~(1u << bl);
                for (uint l = 0u; l < 4u; ++l) {
                    if ((met & (1u << l)) != 0u && sp < WIDE_STACK) {
                        stk_c[sp] = lane_u(child, l);
                        stk_n[sp] = lane_u(count, l);
                        stk_t[sp] = lane_f(tn, l);
                        ++sp;
                    }
                }
                cur = lane_u(child, bl);
                cnt = lane_u(count, bl);
                continue;
            }
            /* a dead end pops here, inside the node loop, so that the lane
             * walks on with the others instead of waiting out their leaves;
             * the pop after the leaves below is the same code on purpose */
            alive = false;
            while (sp > 0u && !alive) {
                --sp;
                if (stk_t[sp] <= h.t * SLAB_FAR_SCALE) { /* the box test's slack: ties are never culled */
                    cur = stk_c[sp];
                    cnt = stk_n[sp];
                    alive = true;
                }
            }
        }
        if (!alive) break;
        for (uint j = cur, end = cur + cnt; j < end; ++j) {
            uvec3 tri = load_tri(g.tri_base + j); /* leaf order: no ref to follow */
            float t;
            if (!tri_intersect(r, load_vertex(tri.x), load_vertex(tri.y), load_vertex(tri.z), t)) continue;
            if (t > h.t) continue;
            uint prim = refs.r[g.ref_base + j];
            if (t == h.t && !key_less(inst, geom_id, prim, h)) continue;
            h.t = t;
            h.prim = prim;
            h.geom = geom_id;
            h.inst = inst;
            h.slot = g.tri_base + j;
            found = true;
        }
        alive = false;
        while (sp > 0u && !alive) {
            --sp;
            if (stk_t[sp] <= h.t * SLAB_FAR_SCALE) { /* the box test's slack: ties are never culled */
                cur = stk_c[sp];
                cnt = stk_n[sp];
                alive = true;
            }
        }
    }
    return found;
}

/* p' = R p + t with rows (R | t); C order of rc__rot_apply_f, then + t. */
vec3 xform_point(vec4 r0, vec4 r1, vec4 r2, vec3 p)
{
    precise float x = r0.x * p.x + r0.y * p.y + r0.z * p.z;
    precise float y = r1.x * p.x + r1.y * p.y + r1.z * p.z;
    precise float z = r2.x * p.x + r2.y * p.y + r2.z * p.z;
    precise float xx = x + r0.w;
    precise float yy = y + r1.w;
    precise float zz = z + r2.w;
    return vec3(xx, yy, zz);
}

vec3 rot_apply(vec4 r0, vec4 r1, vec4 r2, vec3 p)
{
    precise float x = r0.x * p.x + r0.y * p.y + r0.z * p.z;
    precise float y = r1.x * p.x + r1.y * p.y + r1.z * p.z;
    precise float z = r2.x * p.x + r2.y * p.y + r2.z * p.z;
    return vec3(x, y, z);
}

#if RC_RAY_QUERY
/* The nearest hit from the driver's acceleration structure: a top level of
 * one instance per rangecast instance (custom index = instance id + 1) and
 * one for the scene's own meshes (custom index 0), each over a bottom level
 * whose geometry k is mesh k of its scene with its triangles in leaf order,
 * so the primitive index is the leaf slot of the packed arrays. Opaque
 * triangles only, no culling, [0, h.t] as the walk above. */
bool trace_scene(vec3 org, vec3 dir, inout Hit h)
{
    rayQueryEXT q;
    rayQueryInitializeEXT(q, tlas, gl_RayFlagsOpaqueEXT, 0xFFu, org, 0.0, dir, h.t);
    while (rayQueryProceedEXT(q)) {
    }
    if (rayQueryGetIntersectionTypeEXT(q, true) != gl_RayQueryCommittedIntersectionTriangleEXT) return false;
    uint custom = uint(rayQueryGetIntersectionInstanceCustomIndexEXT(q, true));
    uint k = uint(rayQueryGetIntersectionGeometryIndexEXT(q, true));
    uint j = uint(rayQueryGetIntersectionPrimitiveIndexEXT(q, true));
    uint gi = k, inst = RC_INVALID_ID;
    if (custom != 0u) {
        inst = custom - 1u;
        gi = insts.i[inst].first_geom + k;
    }
    Geom g = geoms.g[gi];
    h.t = rayQueryGetIntersectionTEXT(q, true);
    h.prim = refs.r[g.ref_base + j];
    h.geom = k; /* the geometry id within its own scene */
    h.inst = inst;
    h.slot = g.tri_base + j;
    return true;
}
#else
/* rc__scene_intersect: the top level over geometries and instances. Written
 * with one call of trace_mesh (it is inlined: one copy of the traversal):
 * the outer loop takes one item at a time, from the leaf last found by the
 * top-level walk (or item 0 for a scene of one mesh and no instances). */
bool trace_scene(vec3 org, vec3 dir, inout Hit h)
{
    Ray r = make_ray(org, dir);
    Slab s = make_slab(r);
    uint stk[MAX_DEPTH + 1u];
    uint sp = 0u, ni = 0u;
    uint pending = 0u, left = 0u; /* items of the current top leaf */
    bool walking = (pc.flags & 1u) == 0u, found = false;
    if (!walking) left = 1u; /* item 0: refs are not needed */
    for (;;) {
        while (left == 0u && walking) {
            Node n = load_node(pc.top_node + ni);
            float tn;
            bool hit = node_hit(n, s, h.t, tn);
            if (hit && n.count == 0u) {
                if (sp <= MAX_DEPTH) stk[sp++] = n.index + 1u;
                ni = n.index;
                continue;
            }
            if (hit) {
                pending = pc.top_ref + n.index;
                left = n.count;
            }
            if (sp == 0u)
                walking = false;
            else
                ni = stk[--sp];
        }
        if (left == 0u) break;
        uint item = (pc.flags & 1u) != 0u ? 0u : refs.r[pending];
        ++pending;
        --left;
        Ray lr = r;
        Slab ls = s;
        uint first = item, cnt = 1u, inst = RC_INVALID_ID;
        if (item >= pc.geom_count) {
            inst = item - pc.geom_count;
            Inst in_ = insts.i[inst];
            lr = make_ray(xform_point(in_.to_local[0], in_.to_local[1], in_.to_local[2], org),
                          rot_apply(in_.to_local[0], in_.to_local[1], in_.to_local[2], dir));
            ls = make_slab(lr);
            first = in_.first_geom;
            cnt = in_.geom_count;
        }
        for (uint g = 0u; g < cnt; ++g)
            if (trace_mesh(lr, ls, first + g, inst == RC_INVALID_ID ? item : g, inst, h)) found = true;
    }
    return found;
}
#endif /* RC_RAY_QUERY */

/* ---- rays of the sensor ---------------------------------------------------- */

float rayf(uint i) { return uintBitsToFloat(rays.r[i]); }

#if RC_FP64
double rayd(uint i) { return packDouble2x32(uvec2(rays.r[i], rays.r[i + 1u])); }

/* float(x), and it stays rounded. glslang marks no conversion precise, so a
 * driver may fold a later double(float(x)) back to x (Mesa 25's lavapipe
 * does: every float64 refinement then started from unrounded directions, a
 * float ulp off the host's ranges on 15% of the rays). The host never does;
 * an OR with a zero the compiler cannot see (bit 31 of pc.flags, which the
 * host never sets) keeps the rounding. */
float f32(double x)
{
    return uintBitsToFloat(floatBitsToUint(float(x)) | (pc.flags & RC_FLAGS_NEVER_SET));
}

/* store_unit of sensor_rays.c: normalised in double, rounded to float */
vec3 unit(double x, double y, double z)
{
    precise double n = sqrt(x * x + y * y + z * z);
    precise double ux = x / n;
    precise double uy = y / n;
    precise double uz = z / n;
    return vec3(f32(ux), f32(uy), f32(uz));
}
#else
vec3 unit(float x, float y, float z)
{
    precise float n = sqrt(x * x + y * y + z * z);
    return vec3(div_rn(x, n), div_rn(y, n), div_rn(z, n));
}
#endif

/* Direction (unit, sensor frame) and origin of ray `ray` of the scan.
 * Grid tables (vulkan_sensor.c): 2 floats per column, then 2 per row; after
 * them the same values as doubles (the float64 kernel reproduces the CPU's
 * double computation of each direction exactly). */
vec3 sensor_ray(uint ray, out vec3 org)
{
    org = vec3(0.0);
    if (MODEL == MODEL_O1DN || MODEL == MODEL_ONDN) {
        uint j = ray * 3u;
        if (MODEL == MODEL_ONDN) {
            uint o = pc.rays * 3u + j;
            org = vec3(rayf(o), rayf(o + 1u), rayf(o + 2u));
        }
        return vec3(rayf(j), rayf(j + 1u), rayf(j + 2u));
    }
    uint row = ray / pc.columns, col = ray - row * pc.columns;
#if RC_FP64
    uint db = 2u * (pc.columns + pc.grid_rows);
    uint cb = db + 4u * col, rb = db + 4u * (pc.columns + row);
    double c0 = rayd(cb), c1 = rayd(cb + 2u), r0 = rayd(rb), r1 = rayd(rb + 2u);
    if (MODEL == MODEL_SPHERICAL) {
        /* (cos phi cos theta, cos phi sin theta, sin phi) */
        precise double x = r0 * c0;
        precise double y = r0 * c1;
        return unit(x, y, r1);
    }
    if (MODEL == MODEL_CYLINDRICAL) return unit(c0, c1, r0);
    if (MODEL == MODEL_PINHOLE_OPT) return unit(c0, r0, 1.0lf);
    return unit(1.0lf, -c0, -r0); /* body frame: (o.z, -o.x, -o.y) */
#else
    uint cb = 2u * col, rb = 2u * (pc.columns + row);
    float c0 = rayf(cb), c1 = rayf(cb + 1u), r0 = rayf(rb), r1 = rayf(rb + 1u);
    if (MODEL == MODEL_SPHERICAL) {
        precise float x = r0 * c0;
        precise float y = r0 * c1;
        return vec3(x, y, r1);
    }
    if (MODEL == MODEL_CYLINDRICAL) return unit(c0, c1, r0);
    if (MODEL == MODEL_PINHOLE_OPT) return unit(c0, r0, 1.0);
    return unit(1.0, -c0, -r0);
#endif
}

/* ---- results ---------------------------------------------------------------- */

vec3 hit_normal(Hit h)
{
    uvec3 tri = load_tri(h.slot);
    vec3 a = load_vertex(tri.x), b = load_vertex(tri.y), c = load_vertex(tri.z);
    precise float e1x = b.x - a.x;
    precise float e1y = b.y - a.y;
    precise float e1z = b.z - a.z;
    precise float e2x = c.x - a.x;
    precise float e2y = c.y - a.y;
    precise float e2z = c.z - a.z;
    precise float nx = e1y * e2z - e1z * e2y;
    precise float ny = e1z * e2x - e1x * e2z;
    precise float nz = e1x * e2y - e1y * e2x;
    vec3 n = vec3(nx, ny, nz);
    if (h.inst != RC_INVALID_ID) {
        Inst in_ = insts.i[h.inst];
        n = rot_apply(in_.n2w[0], in_.n2w[1], in_.n2w[2], n);
    }
#if RC_FP64
    precise double len = sqrt(double(n.x) * double(n.x) + double(n.y) * double(n.y) + double(n.z) * double(n.z));
    if (len > 0.0lf) n = vec3(float(double(n.x) / len), float(double(n.y) / len), float(double(n.z) / len));
#else
    precise float len = sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
    if (len > 0.0) n = vec3(div_rn(n.x, len), div_rn(n.y, len), div_rn(n.z, len));
#endif
    return n;
}

#if RC_FP64
/* Element i (0..8: R row-major, 9..11: t) of pose's transform in double. */
double xform_d(uint pose, uint i)
{
    uvec4 q = xforms.x[XFORM_UVEC4S * pose + 3u + i / 2u];
    return packDouble2x32((i & 1u) == 0u ? q.xy : q.zw);
}

double inst_d(Inst in_, uint i)
{
    return packDouble2x32(uvec2(in_.to_world_d[2u * i], in_.to_world_d[2u * i + 1u]));
}

/* rc__scene_hit_distance_d, with rc__write_result's rule for using it: the
 * hit's distance recomputed in double against its triangle's plane (through
 * the instance's transform in double). */
float refine_t(Hit h, uint pose, vec3 ds, vec3 os)
{
    double od[3], dd[3];
    dvec3 v[3];
    for (uint a = 0u; a < 3u; ++a) {
        double r0 = xform_d(pose, 3u * a), r1 = xform_d(pose, 3u * a + 1u), r2 = xform_d(pose, 3u * a + 2u);
        precise double d = r0 * double(ds.x) + r1 * double(ds.y) + r2 * double(ds.z);
        precise double o = xform_d(pose, 9u + a);
        if (MODEL == MODEL_ONDN) o += r0 * double(os.x) + r1 * double(os.y) + r2 * double(os.z);
        dd[a] = d;
        od[a] = o;
    }
    uvec3 tri = load_tri(h.slot);
    vec3 p[3];
    p[0] = load_vertex(tri.x);
    p[1] = load_vertex(tri.y);
    p[2] = load_vertex(tri.z);
    if (h.inst != RC_INVALID_ID) {
        Inst in_ = insts.i[h.inst];
        for (uint i = 0u; i < 3u; ++i) {
            precise double x = inst_d(in_, 0u) * double(p[i].x) + inst_d(in_, 1u) * double(p[i].y) +
                               inst_d(in_, 2u) * double(p[i].z) + inst_d(in_, 9u);
            precise double y = inst_d(in_, 3u) * double(p[i].x) + inst_d(in_, 4u) * double(p[i].y) +
                               inst_d(in_, 5u) * double(p[i].z) + inst_d(in_, 10u);
            precise double z = inst_d(in_, 6u) * double(p[i].x) + inst_d(in_, 7u) * double(p[i].y) +
                               inst_d(in_, 8u) * double(p[i].z) + inst_d(in_, 11u);
            v[i] = dvec3(x, y, z);
        }
    } else {
        for (uint i = 0u; i < 3u; ++i) v[i] = dvec3(p[i]);
    }
    precise double e1x = v[1].x - v[0].x;
    precise double e1y = v[1].y - v[0].y;
    precise double e1z = v[1].z - v[0].z;
    precise double e2x = v[2].x - v[0].x;
    precise double e2y = v[2].y - v[0].y;
    precise double e2z = v[2].z - v[0].z;
    precise double nx = e1y * e2z - e1z * e2y;
    precise double ny = e1z * e2x - e1x * e2z;
    precise double nz = e1x * e2y - e1y * e2x;
    precise double dn = nx * dd[0] + ny * dd[1] + nz * dd[2];
    precise double w = nx * (v[0].x - od[0]) + ny * (v[0].y - od[1]) + nz * (v[0].z - od[2]);
    if (dn == 0.0lf) return h.t;
    precise double td = w / dn;
    if (isinf(td) || isnan(td)) return h.t;
    /* a crossing further from t than rounding takes a hit
     * (RC__REFINE_NEAR) and far from the corners' depths along the ray
     * lies off the triangle (the ray runs along its plane): the traversal's
     * t stays (rc__scene_hit_distance_d) */
    if (abs(td - double(h.t)) > double(h.t) * (1.0lf / 4096.0lf)) {
        precise double da = ((v[0].x - od[0]) * dd[0] + (v[0].y - od[1]) * dd[1]) + (v[0].z - od[2]) * dd[2];
        precise double sb = abs((e1x * dd[0] + e1y * dd[1]) + e1z * dd[2]);
        precise double sc = abs((e2x * dd[0] + e2y * dd[1]) + e2z * dd[2]);
        if (abs(td - da) > 2.0lf * (sb + sc) + double(h.t) * (1.0lf / 4096.0lf)) return h.t;
    }
    /* the plane's distance is the better one; a non-positive value (origin
     * on the plane) keeps the traversal's t */
    /* f32: noise on the device widens the range to double again */
    return td > 0.0lf && td < 3.0e38lf && float(td) > 0.0 ? f32(td) : h.t;
}
#else
/* Without float64: the hit's distance against its triangle's plane in float,
 * in the frame the hit was found in (an instance's local frame keeps the ray
 * parameter), used as the CPU uses its double one. Better than the
 * traversal's t on slivers, not as good as double. */
float refine_t(Hit h, vec3 org, vec3 dir)
{
    vec3 o = org, d = dir;
    if (h.inst != RC_INVALID_ID) {
        Inst in_ = insts.i[h.inst];
        o = xform_point(in_.to_local[0], in_.to_local[1], in_.to_local[2], org);
        d = rot_apply(in_.to_local[0], in_.to_local[1], in_.to_local[2], dir);
    }
    uvec3 tri = load_tri(h.slot);
    vec3 a = load_vertex(tri.x), b = load_vertex(tri.y), c = load_vertex(tri.z);
    precise vec3 e1 = b - a;
    precise vec3 e2 = c - a;
    precise float nx = e1.y * e2.z - e1.z * e2.y;
    precise float ny = e1.z * e2.x - e1.x * e2.z;
    precise float nz = e1.x * e2.y - e1.y * e2.x;
    precise float w = nx * (a.x - o.x) + ny * (a.y - o.y) + nz * (a.z - o.z);
    precise float dn = nx * d.x + ny * d.y + nz * d.z;
    if (dn == 0.0) return h.t;
    precise float td = div_rn(w, dn);
    /* a sliver's float normal is poor: there the traversal's t is kept */
    return td > 0.0 && td < 3.0e38 && abs(td - h.t) <= 1e-5 * td ? td : h.t;
}
#endif

/* ---- noise (results kept on the device) -------------------------------------- */

#include "noise.glsl"

/* noise.c's noise_task for one return: element k's draws are uniforms 3k and
 * 3k + 1 (the normal) and 3k + 2 (dropout). true when the return is lost;
 * else range and pt moved along the ray (origin o, sensor frame) as move()
 * moves them, in double where the device has it. */
bool apply_noise(uvec2 k3, vec3 o, inout float range, inout vec3 pt)
{
    uvec2 key = uvec2(pc.noise_key_lo, pc.noise_key_hi);
    if ((pc.noise_flags & NOISE_DROPS) != 0u) {
        uvec2 m = noise_bits(key, add64(k3, uvec2(2u, 0u)));
        if (m.y < pc.noise_drop_hi || (m.y == pc.noise_drop_hi && m.x < pc.noise_drop_lo)) return true;
    }
    if ((pc.noise_flags & NOISE_MOVES) == 0u || (ATTRS & (ATTR_RANGES | ATTR_POINTS)) == 0u) return false;
    float z = noise_normal(key, k3);
#if RC_FP64
    double r;
    if ((ATTRS & ATTR_RANGES) != 0u) {
        r = double(range);
    } else {
        precise double dx = double(pt.x) - double(o.x);
        precise double dy = double(pt.y) - double(o.y);
        precise double dz = double(pt.z) - double(o.z);
        r = sqrt(dx * dx + dy * dy + dz * dz);
    }
    double e = double(pc.noise_exponent);
    double scale = e == 0.0lf ? 1.0lf : e == 1.0lf ? r : (r > 0.0lf ? exp_d(e * log_d(r)) : 0.0lf);
    precise double spread = double(pc.noise_sigma) * scale * double(z);
    if (isnan(spread)) spread = 0.0lf;
    precise double moved = r + double(pc.noise_mean) + spread;
    moved = max(moved, double(pc.range_min));
    moved = min(moved, double(pc.range_max));
    range = float(moved);
    if (r > 0.0lf) {
        precise double f = moved / r;
        precise double px = double(o.x) + (double(pt.x) - double(o.x)) * f;
        precise double py = double(o.y) + (double(pt.y) - double(o.y)) * f;
        precise double pz = double(o.z) + (double(pt.z) - double(o.z)) * f;
        pt = vec3(float(px), float(py), float(pz));
    }
#else
    float r = (ATTRS & ATTR_RANGES) != 0u ? range : length(pt - o);
    float e = pc.noise_exponent;
    float scale = e == 0.0 ? 1.0 : e == 1.0 ? r : (r > 0.0 ? pow(r, e) : 0.0);
    precise float spread = pc.noise_sigma * scale * z;
    if (isnan(spread)) spread = 0.0;
    precise float moved = r + pc.noise_mean + spread;
    moved = clamp(moved, pc.range_min, pc.range_max);
    range = moved;
    if (r > 0.0) pt = o + (pt - o) * div_rn(moved, r);
#endif
    return false;
}

void main()
{
    uint gid = (gl_WorkGroupID.y * pc.groups_x + gl_WorkGroupID.x) * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
    if (gid >= pc.count) return;
    uint rr = pc.first_ray + gid;
    uint pose = pc.first_pose + rr / pc.rays;
    uint ray = rr % pc.rays;

    vec3 os;
    vec3 ds = sensor_ray(ray, os);
    vec4 r0 = uintBitsToFloat(xforms.x[XFORM_UVEC4S * pose]);
    vec4 r1 = uintBitsToFloat(xforms.x[XFORM_UVEC4S * pose + 1u]);
    vec4 r2 = uintBitsToFloat(xforms.x[XFORM_UVEC4S * pose + 2u]);
    vec3 dir = rot_apply(r0, r1, r2, ds);
    vec3 org = MODEL == MODEL_ONDN ? xform_point(r0, r1, r2, os) : vec3(r0.w, r1.w, r2.w);

    Hit h;
    h.t = pc.range_max;
    h.prim = RC_INVALID_ID;
    h.geom = RC_INVALID_ID;
    h.inst = RC_INVALID_ID;
    h.slot = 0u;
    bool found;
    if ((pc.flags & RC_FLAGS_SKIP_WALK) == 0u) {
        found = trace_scene(org, dir, h);
    } else { /* measurements only: what the rest costs */
        found = true;
        h.t = 0.5 * pc.range_max;
        h.prim = 0u;
        h.geom = 0u;
    }

    float t = h.t;
    bool refine = found && (pc.flags & RC_FLAGS_SKIP_REFINE) == 0u;
#if RC_FP64
    if (refine) t = refine_t(h, pose, ds, os);
#else
    if (refine) t = refine_t(h, org, dir);
#endif
    bool valid = found && t >= pc.range_min && t <= pc.range_max;
    float range = valid ? t : (found && t < pc.range_min ? uintBitsToFloat(0xFF800000u) : uintBitsToFloat(0x7F800000u));
    const uint nan_bits = 0x7FC00000u;
    vec3 pt = vec3(0.0);
    if (valid) {
        precise float px = ds.x * range;
        precise float py = ds.y * range;
        precise float pz = ds.z * range;
        if (MODEL == MODEL_ONDN) {
            px += os.x;
            py += os.y;
            pz += os.z;
        }
        pt = vec3(px, py, pz);
    }
    if ((pc.noise_flags & NOISE_ON) != 0u && valid && (ATTRS & ~ATTR_INST_IDS) != 0u) {
        uint klo, khi;
        umulExtended(pose, pc.rays, khi, klo);
        uvec2 k3 = mul64(add64(uvec2(klo, khi), uvec2(ray, 0u)), uvec2(3u, 0u));
        if (apply_noise(k3, MODEL == MODEL_ONDN ? os : vec3(0.0), range, pt)) {
            valid = false;
            range = uintBitsToFloat(0x7F800000u);
        }
    }

    if ((ATTRS & ATTR_HITS) != 0u) outb.o[pc.off_hits + gid] = valid ? 1u : 0u;
    if ((ATTRS & ATTR_RANGES) != 0u) outb.o[pc.off_ranges + gid] = floatBitsToUint(range);
    if ((ATTRS & ATTR_POINTS) != 0u) {
        uint o = pc.off_points + 3u * gid;
        outb.o[o] = valid ? floatBitsToUint(pt.x) : nan_bits;
        outb.o[o + 1u] = valid ? floatBitsToUint(pt.y) : nan_bits;
        outb.o[o + 2u] = valid ? floatBitsToUint(pt.z) : nan_bits;
    }
    if ((ATTRS & ATTR_NORMALS) != 0u) {
        uint o = pc.off_normals + 3u * gid;
        if (valid) {
            vec3 nw = hit_normal(h);
            /* R^T n: the normal in the sensor frame, facing the sensor */
            precise float nx = r0.x * nw.x + r1.x * nw.y + r2.x * nw.z;
            precise float ny = r0.y * nw.x + r1.y * nw.y + r2.y * nw.z;
            precise float nz = r0.z * nw.x + r1.z * nw.y + r2.z * nw.z;
            precise float d = nx * ds.x + ny * ds.y + nz * ds.z;
            if (d > 0.0) {
                nx = -nx;
                ny = -ny;
                nz = -nz;
            }
            outb.o[o] = floatBitsToUint(nx);
            outb.o[o + 1u] = floatBitsToUint(ny);
            outb.o[o + 2u] = floatBitsToUint(nz);
        } else {
            outb.o[o] = nan_bits;
            outb.o[o + 1u] = nan_bits;
            outb.o[o + 2u] = nan_bits;
        }
    }
    if ((ATTRS & ATTR_PRIM_IDS) != 0u) outb.o[pc.off_prim + gid] = valid ? h.prim : RC_INVALID_ID;
    if ((ATTRS & ATTR_GEOM_IDS) != 0u) outb.o[pc.off_geom + gid] = valid ? h.geom : RC_INVALID_ID;
    if ((ATTRS & ATTR_INST_IDS) != 0u) outb.o[pc.off_inst + gid] = valid ? h.inst : RC_INVALID_ID;
}
