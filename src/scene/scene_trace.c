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

double rc__scene_hit_distance_d(const rc_scene *scene, const rc__hit *hit, const double org[3], const double dir[3])
{
    const rc__xformf *x;
    const rc__mesh *mesh = hit_mesh(scene, hit, &x);
    const uint32_t *tri = hit_triangle(mesh, hit);
    double v[3][3], e1[3], e2[3], n[3], dn, w;
    int i, k;
    for (i = 0; i < 3; ++i) {
        const float *p = mesh->vertices + (size_t)tri[i] * mesh->stride;
        if (x) {
            for (k = 0; k < 3; ++k)
                v[i][k] = x->rd[3 * k] * p[0] + x->rd[3 * k + 1] * p[1] + x->rd[3 * k + 2] * p[2] + x->td[k];
        } else {
            for (k = 0; k < 3; ++k) v[i][k] = p[k];
        }
    }
    for (k = 0; k < 3; ++k) {
        e1[k] = v[1][k] - v[0][k];
        e2[k] = v[2][k] - v[0][k];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    dn = n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2];
    w = n[0] * (v[0][0] - org[0]) + n[1] * (v[0][1] - org[1]) + n[2] * (v[0][2] - org[2]);
    if (dn == 0.0 || !isfinite(w / dn)) return hit->t;
    return w / dn;
}
