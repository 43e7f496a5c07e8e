/* The rangecast program: what every subcommand shares (argument parsing,
 * messages and exit codes, setting up a context sized exactly for its work). */
#ifndef RCP_TOOL_H
#define RCP_TOOL_H

#include <stddef.h>
#include <stdint.h>

#include "meshgen.h"
#include "rangecast/rangecast.h"

#define RCP_EXIT_OK    0
#define RCP_EXIT_FAIL  1 /* a library or file error */
#define RCP_EXIT_USAGE 2 /* bad arguments */

#if defined(__GNUC__)
#define RCP_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define RCP_PRINTF(a, b)
#endif

/* Subcommands: argv[0] is the subcommand's name. */
int rcp_cmd_simulate(int argc, char **argv);
int rcp_cmd_bench(int argc, char **argv);
int rcp_cmd_demo(int argc, char **argv);
int rcp_cmd_info(int argc, char **argv);
int rcp_cmd_bake(int argc, char **argv);
int rcp_cmd_gen(int argc, char **argv);

/* "rangecast CMD: message" + a pointer to --help on stderr; returns RCP_EXIT_USAGE. */
int rcp_usage_error(const char *cmd, const char *fmt, ...) RCP_PRINTF(2, 3);
/* "rangecast CMD: message" on stderr; returns RCP_EXIT_FAIL. */
int rcp_fail(const char *cmd, const char *fmt, ...) RCP_PRINTF(2, 3);
/* A failed library call: "rangecast CMD: CALL: <rc_status_string>: <last error>";
 * returns RCP_EXIT_FAIL. ctx may be NULL. */
int rcp_lib_error(const char *cmd, const rc_context *ctx, const char *call, rc_status st);

/* Arguments. rcp_opt matches argv[*i] against "--name VALUE" or "--name=VALUE":
 * returns 1 and sets *value (advancing *i past a separate value), 0 when it is
 * another argument, -1 when the value is missing (message printed). */
int rcp_opt(int argc, char **argv, int *i, const char *name, const char **value);
int rcp_is_help(const char *arg);
/* --threads N (0..RC_MAX_THREADS): as rcp_opt, and -1 (message printed) for a
 * bad number too. */
int rcp_opt_threads(const char *cmd, int argc, char **argv, int *i, uint32_t *threads);
/* Numbers; 0 on success, -1 on a malformed or out-of-range value (no message). */
int rcp_parse_u32(const char *s, uint32_t *out);
/* A count with an optional suffix: 1k = 1000, 1M = 10^6, 1G = 10^9. */
int rcp_parse_count(const char *s, uint64_t *out);
int rcp_parse_float(const char *s, float *out);
/* Exactly n comma-separated floats. */
int rcp_parse_floats(const char *s, float *out, int n);
/* bvh | embree | vulkan | auto -> RC_BACKEND_*; prints an error that lists the
 * backends built into this library and returns -1 when unknown or absent. */
int rcp_parse_backend(const char *cmd, const char *s, uint32_t *backend);
/* "bvh, embree" ... : the backends built in. */
const char *rcp_available_backends(char *buf, size_t size);
/* balanced | fast | high | compact -> RC_BUILD_*, or -1 with a message. */
int rcp_parse_build_quality(const char *cmd, const char *s, uint32_t *quality);
/* RC_BUILD_* -> its name ("unknown" past the last). */
const char *rcp_build_quality_name(uint32_t quality);
/* A preset name -> RC_PRESET_*, or -1 with a message listing the presets. */
int rcp_parse_sensor(const char *cmd, const char *s, uint32_t *preset);

/* A context sized exactly for one scene holding `mesh` (referenced in place,
 * so the mesh must outlive the world) and the given sensor presets. */
#define RCP_MAX_SENSORS 4
typedef struct rcp_world {
    rc_context *ctx;
    rc_scene *scene;                     /* NULL when no mesh was given */
    rc_sensor *sensors[RCP_MAX_SENSORS];
    uint32_t sensor_count;
    uint32_t backend;                    /* the backend in use */
    uint32_t threads;                    /* threads simulate uses */
    size_t arena_bytes;                  /* desc.memory_size we asked for */
    size_t scene_bytes;                  /* rc_scene_memory_requirements */
    double build_s;                      /* wall time of rc_scene_commit (rc_scene_load_baked for a .rcmap) */
    rcu_mesh *parts;                     /* bench --meshes N > 1: the map's N meshes (geometries 0 .. N-1) */
    uint32_t part_count;
} rcp_world;

/* Creates the world; on failure prints the error (as cmd) and returns
 * RCP_EXIT_FAIL with *world cleaned up. */
/* --device of bench/simulate: the Vulkan device (rc_context_desc.device); NULL = default. */
extern const char *rcp_device;
/* rc_context_desc.flags of the contexts the commands make (bench
 * --vulkan-traversal ray-query: RC_CONTEXT_VULKAN_RAY_QUERY). */
extern uint32_t rcp_context_flags;
/* --build-quality of bench: the scene's rc_scene_desc.build_quality (RC_BUILD_*). */
extern uint32_t rcp_build_quality;
/* --mesh of bench and simulate: how the map's mesh is handed in,
 * RC_MESH_REFERENCE (the default: used in place) or RC_MESH_COPY (copied into
 * the arena). rcp_parse_mesh_mode sets it from the option's value ("reference"
 * or "copy"); -1 after a usage error naming cmd. */
extern uint32_t rcp_mesh_flags;
int rcp_parse_mesh_mode(const char *cmd, const char *value);
/* --meshes of bench: the map cut into this many meshes of consecutive
 * triangles, each a geometry with its own vertices (rcu_mesh_split); 1 = the
 * map as one mesh. */
extern uint32_t rcp_mesh_parts;
/* 1 (bench, simulate): the contexts get RC_SIMULATE_SCRATCH_PER_THREAD a
 * thread beyond the exact requirements, so that calls on maps larger than the
 * cache run ordered; 0 (info, demo): the exact figure. */
extern int rcp_order_room;

int rcp_world_create(const char *cmd, uint32_t backend, uint32_t threads, const rcu_mesh *mesh,
                     const uint32_t *presets, uint32_t preset_count, rcp_world *world);
/* The same with one OnDn/O1Dn sensor of the caller's rays instead of presets
 * (model RC_SENSOR_ONDN or RC_SENSOR_O1DN); it is world->sensors[0]. */
int rcp_world_create_rays(const char *cmd, uint32_t backend, uint32_t threads, const rcu_mesh *mesh,
                          uint32_t model, const rc_rays_desc *rays, rcp_world *world);
void rcp_world_destroy(rcp_world *world);

/* Exact arena bytes of a context + one scene of this mesh on a backend
 * (threads as given), without building anything; with part_count > 1 the
 * scene holds parts[0 .. part_count) instead (the mesh cut up). */
int rcp_arena_bytes(const char *cmd, uint32_t backend, uint32_t threads, const rcu_mesh *mesh,
                    const rcu_mesh *parts, uint32_t part_count, const uint32_t *presets, uint32_t preset_count,
                    size_t *total, size_t *scene_bytes);

/* Median of v[0..n) (sorts v); NaN when n is 0. */
double rcp_median(double *v, size_t n);

/* "1,234,567" into buf. */
const char *rcp_thousands(uint64_t v, char *buf, size_t size);
/* "12.3 MiB" into buf. */
const char *rcp_bytes(uint64_t v, char *buf, size_t size);

#endif
