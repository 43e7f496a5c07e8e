/* rcutil: the stability cases, the scenes where ray casters fail, shared by the
 * cmocka suite (tests/test_stability.c) and `rangecast stability`. Each case
 * builds a scene, a sensor (O1Dn rays) and poses, runs the library on a
 * backend and checks every ray against the float64 reference tracer
 * (reftrace.h) over the same scene flattened in (instance, geometry, triangle)
 * order, instance transforms applied in double.
 *
 * A ray is wrong when any of these holds:
 * - its class differs from the reference's: a return, no return (+inf), or a
 *   hit nearer than range_min (-inf);
 * - both return and |range - t_ref| > tol_abs + tol_rel * t_ref;
 * - a return with a NaN/inf range, point or normal;
 * - a normal that is not unit (1e-4), not perpendicular to the reference
 *   face (|n . n_ref| < 1 - 1e-5) or not facing the sensor;
 * - a hit on a zero-area triangle, or ids past the scene;
 * - in the cases that ask for it (coplanar overlaps): an (instance, geometry,
 *   triangle) key other than the reference's, the smallest of the tie. */
#ifndef RCU_STABILITY_CASES_H
#define RCU_STABILITY_CASES_H

#include <stdint.h>

#include "rangecast/rangecast.h"

#define RCU_STAB_GRAZING        0
#define RCU_STAB_DEGENERATE     1
#define RCU_STAB_ON_SURFACE     2
#define RCU_STAB_AXIS_PARALLEL  3
#define RCU_STAB_LONG_SHORT     4
#define RCU_STAB_INSTANCE_SCALE 5
#define RCU_STAB_FAR_ORIGIN     6
#define RCU_STAB_COPLANAR       7
#define RCU_STAB_CASE_COUNT     8

/* Called after the context is created, before the scene is built (e.g. to
 * switch Embree's robust mode through the internal options in a test). */
typedef void (*rcu_stab_configure_fn)(rc_context *ctx, void *user);

typedef struct rcu_stab_options {
    uint32_t backend;        /* RC_BACKEND_* */
    uint32_t context_flags;  /* rc_context_desc.flags (RC_CONTEXT_VULKAN_RAY_QUERY) */
    uint32_t threads;        /* library threads (0 = all CPUs) */
    int quick;               /* smaller sizes (sanitizer runs) */
    rcu_stab_configure_fn configure; /* optional */
    void *configure_user;
} rcu_stab_options;

typedef struct rcu_stab_result {
    uint64_t rays;           /* rays checked */
    uint64_t wrong;          /* rays failing any check (below: by kind; a ray may count in several) */
    uint64_t class_mismatch; /* return / +inf / -inf differs from the reference */
    uint64_t range_errors;   /* both return, error over the tolerance */
    uint64_t nan_outputs;    /* non-finite range, point or normal on a return */
    uint64_t bad_normals;
    uint64_t degenerate_hits;
    uint64_t key_mismatch;   /* ids other than the reference's (where the case checks them) */
    double max_err;          /* largest |range - t_ref| over rays both return (m) */
    double tol_abs, tol_rel; /* the case's tolerance */
    char note[256];          /* the first wrong ray, or the library error */
} rcu_stab_result;

/* Short name ("grazing", ...) and a one-line description. NULL past the end. */
const char *rcu_stab_case_name(int index);
const char *rcu_stab_case_about(int index);

/* Runs one case. 0 when it ran (wrong rays are in *out, not an error); -1
 * when the library or the reference failed (out->note says why). The caller
 * checks rc_backend_available first. */
int rcu_stab_run(int index, const rcu_stab_options *opt, rcu_stab_result *out);

#endif
