/* rcutil: a float64 reference ray caster for triangle meshes, the ground truth
 * the accuracy tools and the stability suite compare the library with. It is
 * never linked into the library and shares no code with it: its own BVH
 * (median split, double bounds) and its own watertight ray/triangle test
 * (Woop, Benthin, Wald 2013, in double, with a long double fallback when an
 * edge function is exactly zero).
 *
 * Rules (the library's, stated once here):
 * - a hit needs t > 0 along the ray (t in units of |d|) and t <= tmax;
 * - zero-area triangles ((b - a) x (c - a) == 0 in double) are never hit;
 * - either winding is hit;
 * - ties at exactly equal t go to the smaller triangle index. Flatten a scene
 *   in (instance, geometry, triangle) order and this is the library's tie
 *   rule.
 * Thread rule: a built tracer is read-only; nearest may run in parallel. */
#ifndef RCU_REFTRACE_H
#define RCU_REFTRACE_H

#include <stdint.h>

#include "meshgen.h"
#include "util.h"

typedef struct rcu_reftrace rcu_reftrace;

/* Builds a tracer over a float mesh (the vertices are copied in double).
 * 0 on success, -1 (rcu_last_error) on an empty mesh, a bad index, no memory. */
int rcu_reftrace_build(const rcu_mesh *mesh, rcu_reftrace **out);

/* The same over double vertices (3 per vertex), e.g. a scene flattened with
 * its instance transforms applied in double. */
int rcu_reftrace_build_d(const double *vertices, uint32_t vertex_count, const uint32_t *indices,
                         uint32_t triangle_count, rcu_reftrace **out);

/* Nearest hit of the ray o + t d with 0 < t <= tmax (d need not be unit).
 * Returns 1 with *t and *prim set, 0 when nothing is hit (outputs untouched). */
int rcu_reftrace_nearest(const rcu_reftrace *rt, const double o[3], const double d[3], double tmax,
                         double *t, uint32_t *prim);

/* Unit geometric normal of a triangle ((b - a) x (c - a), normalised); zeros
 * for a zero-area one. */
void rcu_reftrace_normal(const rcu_reftrace *rt, uint32_t prim, double n[3]);

/* 1 when the triangle has zero area (never hit). */
int rcu_reftrace_degenerate(const rcu_reftrace *rt, uint32_t prim);

uint32_t rcu_reftrace_triangle_count(const rcu_reftrace *rt);

/* NULL is a no-op. */
void rcu_reftrace_free(rcu_reftrace *rt);

#endif
