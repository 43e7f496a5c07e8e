/* Nearest-hit search through a scene's two levels: the top BVH over geometries
 * and instances, then each mesh's BVH (instances in their own frame). */
#include "scene/scene.h"

#include "bvh/intersect.h"

#include <math.h>

/* Slab test against a top-level node. Top-level boxes are few, so this is not
 * the hot loop; NaN from 0 * inf is avoided by the ordered min/max below. */
static int box_hit(const rc__ray *r, const float bmin[3], const float bmax[3], float tmax, float *tnear)
{
    float t0 = 0.0f, t1 = tmax;
    int k;
    for (k = 0; k < 3; ++k) {
        float a = (bmin[k] - r->org[k]) * r->inv_dir[k];
        float b = (bmax[k] - r->org[k]) * r->inv_dir[k];
        float lo = a < b ? a : b, hi = a < b ? b : a;
        if (a != a || b != b) { /* 0 * inf: origin on the slab plane with a parallel ray */
            if (r->org[k] < bmin[k] || r->org[k] > bmax[k]) return 0;
            continue;
        }
        if (lo > t0) t0 = lo;
        if (hi < t1) t1 = hi;
    }
    /* Ize's bound, as in the mesh trees: rounding never rejects a box the ray
     * meets (a smaller margin could cull a mesh that a grazing ray hits, and
     * the packet path, which tests every mesh, would then disagree) */
    *tnear = t0;
    return t0 <= t1 * RC__SLAB_FAR_SCALE;
}

static int instance_intersect(const rc__instance *in, uint32_t inst_id, const rc__ray *ray, rc__hit *hit)
{
    const rc_scene *src = in->source;
    rc__ray local;
    float o[3], d[3];
    uint32_t g;
    int found = 0;
    rc__rot_apply_f(in->to_local.r, ray->org, o);
    o[0] += in->to_local.t[0];
    o[1] += in->to_local.t[1];
    o[2] += in->to_local.t[2];
    rc__rot_apply_f(in->to_local.r, ray->dir, d);
    rc__ray_prepare(&local, o, d);
    /* Sources hold a few meshes: test each mesh's root through its own BVH. */
    for (g = 0; g < src->geom_count; ++g) found |= rc__mesh_intersect(&src->geoms[g].mesh, &local, g, inst_id, hit);
    return found;
}

int rc__scene_intersect(const rc_scene *scene, const rc__ray *ray, rc__hit *hit)
{
    uint32_t stack[RC__BVH_MAX_DEPTH + 1];
    uint32_t sp = 0, ni = 0;
    int found = 0;
    const rc__bvh *top = &scene->top;

    if (scene->geom_count == 1 && scene->inst_count == 0)
        return rc__mesh_intersect(&scene->geoms[0].mesh, ray, 0, RC_INVALID_ID, hit);
    if (top->node_count == 0) return 0;
    for (;;) {
        const rc__bvh_node *n = &top->nodes[ni];
        float tn;
        if (box_hit(ray, n->bmin, n->bmax, hit->t, &tn)) {
            if (n->count == 0) {
                stack[sp++] = n->index + 1; /* depth is capped by the builder */
                ni = n->index;
                continue;
            } else {
                uint32_t k;
                for (k = 0; k < n->count; ++k) {
                    uint32_t item = top->refs[n->index + k];
                    if (item < scene->geom_count)
                        found |= rc__mesh_intersect(&scene->geoms[item].mesh, ray, item, RC_INVALID_ID, hit);
                    else
                        found |= instance_intersect(&scene->insts[item - scene->geom_count],
                                                    item - scene->geom_count, ray, hit);
                }
            }
        }
        if (sp == 0) break;
        ni = stack[--sp];
    }
    return found;
}

void rc__scene_hit_normal(const rc_scene *scene, const rc__hit *hit, float n[3])
{
    float local[3];
    double len;
    if (hit->inst == RC_INVALID_ID) {
        rc__mesh_triangle_normal(&scene->geoms[hit->geom].mesh, hit->prim, local);
        n[0] = local[0];
        n[1] = local[1];
        n[2] = local[2];
    } else {
        const rc__instance *in = &scene->insts[hit->inst];
        rc__mesh_triangle_normal(&in->source->geoms[hit->geom].mesh, hit->prim, local);
        rc__rot_apply_f(in->normal_to_world, local, n);
    }
    len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
    if (len > 0.0) {
        n[0] = (float)(n[0] / len);
        n[1] = (float)(n[1] / len);
        n[2] = (float)(n[2] / len);
    }
}

/* The mesh of a hit and its instance transform (NULL without one). */
static const rc__mesh *hit_mesh(const rc_scene *scene, const rc__hit *hit, const rc__xformf **x)
{
    if (hit->inst == RC_INVALID_ID) {
        *x = NULL;
        return &scene->geoms[hit->geom].mesh;
    }
    *x = &scene->insts[hit->inst].to_world;
    return &scene->insts[hit->inst].source->geoms[hit->geom].mesh;
}

/* The hit triangle's vertex indices: the leaf-ordered copy was just read by
 * the built-in triangle test (cached); the mesh's own index array is a miss on
 * a large map. */
static const uint32_t *hit_triangle(const rc__mesh *mesh, const rc__hit *hit)
{
    return hit->slot != RC_INVALID_ID && mesh->leaf_tris ? mesh->leaf_tris + (size_t)3 * hit->slot
                                                         : mesh->indices + (size_t)3 * hit->prim;
}

void rc__scene_hit_prefetch(const rc_scene *scene, const rc__hit *hit, int stage)
{
    const rc__xformf *x;
    const rc__mesh *mesh = hit_mesh(scene, hit, &x);
    const uint32_t *tri = hit_triangle(mesh, hit);
    int i;
    if (stage == 0) {
        RC__PREFETCH(tri);
        return;
    }
    for (i = 0; i < 3; ++i) RC__PREFETCH(mesh->vertices + (size_t)tri[i] * mesh->stride);
}

/* Written with scalar locals, not arrays: gcc pairs array elements into
 * 16-byte loads of values it had just stored 8 bytes at a time, and the CPU
 * cannot forward two stores into one load (a stall of a dozen cycles or
 * more, which made this function 18% of the time on a 1k map). */
double rc__scene_hit_distance_d(const rc_scene *scene, const rc__hit *hit, const rc__xformf *world,
                                const float dir_s[3], const float *org_s)
{
    const rc__xformf *x;
    const rc__mesh *mesh = hit_mesh(scene, hit, &x);
    const uint32_t *tri = hit_triangle(mesh, hit);
    const float *p0 = mesh->vertices + (size_t)tri[0] * mesh->stride;
    const float *p1 = mesh->vertices + (size_t)tri[1] * mesh->stride;
    const float *p2 = mesh->vertices + (size_t)tri[2] * mesh->stride;
    const double *rd = world->rd;
    const double sx = dir_s[0], sy = dir_s[1], sz = dir_s[2];
    /* the ray in the scene frame, in double */
    const double dx = rd[0] * sx + rd[1] * sy + rd[2] * sz;
    const double dy = rd[3] * sx + rd[4] * sy + rd[5] * sz;
    const double dz = rd[6] * sx + rd[7] * sy + rd[8] * sz;
    double ox = world->td[0], oy = world->td[1], oz = world->td[2];
    double ax, ay, az, bx, by, bz, cx, cy, cz, e1x, e1y, e1z, e2x, e2y, e2z, nx, ny, nz, dn, w;
    if (org_s) {
        const double px = org_s[0], py = org_s[1], pz = org_s[2];
        ox += rd[0] * px + rd[1] * py + rd[2] * pz;
        oy += rd[3] * px + rd[4] * py + rd[5] * pz;
        oz += rd[6] * px + rd[7] * py + rd[8] * pz;
    }
    if (x) {
        const double *r = x->rd, *t = x->td;
        ax = r[0] * p0[0] + r[1] * p0[1] + r[2] * p0[2] + t[0];
        ay = r[3] * p0[0] + r[4] * p0[1] + r[5] * p0[2] + t[1];
        az = r[6] * p0[0] + r[7] * p0[1] + r[8] * p0[2] + t[2];
        bx = r[0] * p1[0] + r[1] * p1[1] + r[2] * p1[2] + t[0];
        by = r[3] * p1[0] + r[4] * p1[1] + r[5] * p1[2] + t[1];
        bz = r[6] * p1[0] + r[7] * p1[1] + r[8] * p1[2] + t[2];
        cx = r[0] * p2[0] + r[1] * p2[1] + r[2] * p2[2] + t[0];
        cy = r[3] * p2[0] + r[4] * p2[1] + r[5] * p2[2] + t[1];
        cz = r[6] * p2[0] + r[7] * p2[1] + r[8] * p2[2] + t[2];
    } else {
        ax = p0[0], ay = p0[1], az = p0[2];
        bx = p1[0], by = p1[1], bz = p1[2];
        cx = p2[0], cy = p2[1], cz = p2[2];
    }
    e1x = bx - ax, e1y = by - ay, e1z = bz - az;
    e2x = cx - ax, e2y = cy - ay, e2z = cz - az;
    nx = e1y * e2z - e1z * e2y;
    ny = e1z * e2x - e1x * e2z;
    nz = e1x * e2y - e1y * e2x;
    dn = nx * dx + ny * dy + nz * dz;
    w = nx * (ax - ox) + ny * (ay - oy) + nz * (az - oz);
    if (dn == 0.0 || !isfinite(w / dn)) return hit->t;
    return w / dn;
}
