/* rangecast gen: the standard workload (and the demo map) as files, so other
 * tools (and other simulators) run on exactly the same input. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ply.h"
#include "poses.h"
#include "tool.h"
#include "util.h"

static void usage(FILE *f)
{
    fprintf(f,
        "Usage: rangecast gen --sphere N [--radius R] -o FILE.ply\n"
        "       rangecast gen --poses N [--radius R] [--seed S] [--center x,y,z] -o FILE.bin|FILE.tum\n"
        "       rangecast gen --demo-map -o FILE.ply\n"
        "\n"
        "  --sphere N     closed UV sphere of about N triangles (1k, 10k, 100k, 1M, 10M ...),\n"
        "                 radius R (default 20 m): the benchmark map\n"
        "  --poses N      N poses uniform in the ball of radius R (default 10 m) about\n"
        "                 --center (default 0,0,0), uniformly random orientations, from\n"
        "                 --seed S (default 1): the benchmark poses, identical on every\n"
        "                 platform. File: float32 LE x y z qx qy qz qw per pose, or for\n"
        "                 .tum/.txt a TUM trajectory: lines 'timestamp x y z qx qy qz qw'.\n"
        "  --demo-map     the demo warehouse\n"
        "  -o FILE        output file\n"
        "  -h, --help     this text\n"
        "\n"
        "'rangecast bench' without --map/--poses uses --sphere 1M --radius 20 and\n"
        "--poses 1000 --radius 10 --seed 1.\n");
}

int rcp_cmd_gen(int argc, char **argv)
{
    const char *cmd = "gen", *out = NULL;
    uint64_t sphere = 0, seed = 1;
    uint32_t poses = 0;
    int demo = 0, have_radius = 0, i, r, kinds;
    float radius = 0.0f, center[3] = {0, 0, 0};
    char n1[32], n2[32];

    for (i = 1; i < argc; i++) {
        const char *v = NULL;
        if (rcp_is_help(argv[i])) {
            usage(stdout);
            return RCP_EXIT_OK;
        }
#define OPT(name) ((r = rcp_opt(argc, argv, &i, name, &v)) != 0)
        if (OPT("--sphere")) {
            if (r < 0) return RCP_EXIT_USAGE;
            if (rcp_parse_count(v, &sphere) != 0 || sphere < 8 || sphere > 4000000000ull)
                return rcp_usage_error(cmd, "--sphere: expected a triangle count 8 .. 4G (k, M, G suffixes), got '%s'", v);
        } else if (OPT("--poses")) {
            if (r < 0) return RCP_EXIT_USAGE;
            if (rcp_parse_u32(v, &poses) != 0 || poses == 0)
                return rcp_usage_error(cmd, "--poses: expected a count >= 1, got '%s'", v);
        } else if (OPT("--radius")) {
            if (r < 0) return RCP_EXIT_USAGE;
            if (rcp_parse_float(v, &radius) != 0 || !(radius > 0.0f))
                return rcp_usage_error(cmd, "--radius: expected metres > 0, got '%s'", v);
            have_radius = 1;
        } else if (OPT("--seed")) {
            if (r < 0) return RCP_EXIT_USAGE;
            if (rcp_parse_count(v, &seed) != 0)
                return rcp_usage_error(cmd, "--seed: expected an unsigned integer, got '%s'", v);
        } else if (OPT("--center")) {
            if (r < 0) return RCP_EXIT_USAGE;
            if (rcp_parse_floats(v, center, 3) != 0)
                return rcp_usage_error(cmd, "--center: expected x,y,z, got '%s'", v);
        } else if (OPT("-o") || (r == 0 && OPT("--output"))) {
            if (r < 0) return RCP_EXIT_USAGE;
            out = v;
        } else if (strcmp(argv[i], "--demo-map") == 0) {
            demo = 1;
        } else {
            return rcp_usage_error(cmd, "unknown argument '%s'", argv[i]);
        }
#undef OPT
    }
    kinds = (sphere != 0) + (poses != 0) + demo;
    if (kinds != 1) return rcp_usage_error(cmd, "give exactly one of --sphere N, --poses N, --demo-map");
    if (!out) return rcp_usage_error(cmd, "-o FILE is required");

    if (poses) {
        rc_pose *p = (rc_pose *)malloc((size_t)poses * sizeof *p);
        int st;
        if (!p) return rcp_fail(cmd, "out of memory for %u poses", poses);
        rcu_poses_random_about(poses, have_radius ? radius : 10.0f, seed, center, p);
        st = rcu_poses_write(out, p, poses);
        free(p);
        if (st != 0) return rcp_fail(cmd, "%s", rcu_last_error());
        printf("%s: %s poses, radius %g m about (%g, %g, %g), seed %llu (", out, rcp_thousands(poses, n1, sizeof n1),
               have_radius ? (double)radius : 10.0, (double)center[0], (double)center[1], (double)center[2],
               (unsigned long long)seed);
        if (rcu_poses_is_tum(out))
            printf("a TUM trajectory, %g s apart)\n", RCU_TUM_PERIOD);
        else
            printf("%s bytes)\n", rcp_thousands((uint64_t)poses * 28u, n2, sizeof n2));
    } else {
        rcu_mesh m;
        int st;
        if (demo) st = rcu_mesh_demo_map(&m);
        else st = rcu_mesh_uv_sphere_triangles(have_radius ? radius : 20.0f, sphere, &m);
        if (st != 0) return rcp_fail(cmd, "%s", rcu_last_error());
        st = rcu_mesh_write_ply(out, &m);
        if (st == 0)
            printf("%s: %s, %s triangles, %s vertices\n", out,
                   demo ? "demo warehouse" : "UV sphere", rcp_thousands(m.triangle_count, n1, sizeof n1),
                   rcp_thousands(m.vertex_count, n2, sizeof n2));
        rcu_mesh_free(&m);
        if (st != 0) return rcp_fail(cmd, "%s", rcu_last_error());
    }
    return RCP_EXIT_OK;
}
