/* The rangecast program: the library's ranges against the float64 reference
 * tracer (reftrace.h), shared by `accuracy` and `lod`. */
#ifndef RCP_ACCURACY_H
#define RCP_ACCURACY_H

#include <stdint.h>
#include <stdio.h>

#include "reference.h"
#include "reftrace.h"
#include "tool.h"

int rcp_cmd_accuracy(int argc, char **argv);
int rcp_cmd_stability(int argc, char **argv);
int rcp_cmd_lod(int argc, char **argv);

/* Angle of incidence bins (degrees between the ray and the reference
 * triangle's normal): [0,30) [30,60) [60,80) [80,89) [89,90]. */
#define RCP_ACC_BINS 5
extern const double rcp_acc_bin_edges[RCP_ACC_BINS + 1];

typedef struct rcp_acc_errs {
    uint64_t n;
    double mean, max, p99, p999;
} rcp_acc_errs;

typedef struct rcp_acc_stats {
    uint64_t rays;
    uint64_t ref_returns, lib_returns; /* valid returns (within [range_min, range_max]) */
    uint64_t disagree;                 /* rays whose +inf / -inf / return class differs */
    uint64_t nan_outputs;              /* NaN ranges (never allowed) */
    rcp_acc_errs all, bin[RCP_ACC_BINS];
    double sim_s;                      /* wall time of the rc_simulate calls */
} rcp_acc_stats;

/* Simulates sensor at poses on the world's scene and compares every ray with
 * the reference (ref traced over the map the ranges should match; rays from
 * rcu_preset_rays_f64 of the same preset). 0 on success, else an exit code
 * with a message printed. */
int rcp_accuracy_run(const char *cmd, const rcp_world *w, const rc_sensor *sensor, const rcu_reftrace *ref,
                     const rcu_preset_rays *rays, const rc_pose *poses, uint32_t pose_count,
                     rcp_acc_stats *out);

/* A number or null (JSON). */
void rcp_json_number(FILE *f, double v);
/* A JSON string with the escapes a path can need. */
void rcp_json_string(FILE *f, const char *s);

#endif
