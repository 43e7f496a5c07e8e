/* rangecast: the command line program. One file per subcommand; this one
 * dispatches and prints the overview. */
#include <stdio.h>
#include <string.h>

#include "accuracy.h"
#include "mesh_load.h"
#include "range_image.h"
#include "tool.h"

static void usage(FILE *f)
{
    char avail[64];
    fprintf(f,
        "rangecast %s: range sensor simulation by ray tracing triangle meshes\n"
        "\n"
        "Usage: rangecast COMMAND [OPTIONS]\n"
        "\n"
        "Commands:\n"
        "  demo       build a demo warehouse, simulate a VLP-16 and a D435 in it, write clouds and images\n"
        "  simulate   simulate a sensor at poses in a mesh map; write a point cloud (and a range image)\n"
        "  bench      scans per second and range accuracy on a map; prints one JSON line\n"
        "  bake       build a map's BVH once and write it as a baked map (.rcmap) that loads in place\n"
        "  info       a map's size and bounds, and per backend its arena bytes and build time\n"
        "  accuracy   every ray against the float64 reference tracer: disagreements, range errors by incidence\n"
        "  stability  the stability cases (grazing, degenerate, far origin ...) per backend against the reference\n"
        "  lod        levels of detail of a map (meshoptimizer): speed, bytes, error; writes the coarsest within tolerance\n"
        "  gen        write the benchmark workload (UV sphere, random poses) or the demo map to files\n"
        "  help       this text ('rangecast COMMAND --help' for a command's options)\n"
        "\n"
        "Backends in this library: %s (auto is bvh).\n"
        "Sensors: vlp16, vlp16-360, os1-64, d435, livox-mid40; ouster:FILE.json (an Ouster unit's metadata).\n"
        "Maps: %s.\n"
        "Images: %s.\n"
        "Exit status: 0 success, 1 a library or file error, 2 bad arguments.\n",
        rc_version_string(), rcp_available_backends(avail, sizeof avail), rcp_mesh_formats(),
        rcp_range_image_has_png() ? "PNG" : "PPM/PGM (built without libpng)");
}

int main(int argc, char **argv)
{
    static const struct {
        const char *name;
        int (*run)(int, char **);
    } commands[] = {{"simulate", rcp_cmd_simulate},
                    {"bench", rcp_cmd_bench},
                    {"demo", rcp_cmd_demo},
                    {"info", rcp_cmd_info},
                    {"bake", rcp_cmd_bake},
                    {"gen", rcp_cmd_gen},
                    {"accuracy", rcp_cmd_accuracy},
                    {"stability", rcp_cmd_stability},
                    {"lod", rcp_cmd_lod}};
    size_t k;
    if (argc < 2) {
        usage(stderr);
        return RCP_EXIT_USAGE;
    }
    if (strcmp(argv[1], "help") == 0 || rcp_is_help(argv[1])) {
        if (argc > 2 && strcmp(argv[1], "help") == 0) {
            for (k = 0; k < sizeof commands / sizeof commands[0]; k++)
                if (strcmp(argv[2], commands[k].name) == 0) {
                    char *sub[2];
                    sub[0] = argv[2];
                    sub[1] = (char *)"--help";
                    return commands[k].run(2, sub);
                }
            return rcp_usage_error(NULL, "unknown command '%s'", argv[2]);
        }
        usage(stdout);
        return RCP_EXIT_OK;
    }
    if (strcmp(argv[1], "--version") == 0 || strcmp(argv[1], "version") == 0) {
        printf("rangecast %s\n", rc_version_string());
        return RCP_EXIT_OK;
    }
    for (k = 0; k < sizeof commands / sizeof commands[0]; k++)
        if (strcmp(argv[1], commands[k].name) == 0) return commands[k].run(argc - 1, argv + 1);
    return rcp_usage_error(NULL, "unknown command '%s'", argv[1]);
}
