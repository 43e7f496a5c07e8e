/* rangecast info: what a map costs: triangles, bounds, problems, and per
 * backend the exact arena bytes and the build time. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "baked_file.h"
#include "mesh_load.h"
#include "tool.h"
#include "util.h"

static void usage(FILE *f)
{
    fprintf(f,
        "Usage: rangecast info --map FILE [--backend B] [--threads N]\n"
        "\n"
        "Prints the map's size, bounds and degenerate triangles, then for each backend\n"
        "built into the library (or only --backend B) the exact arena bytes a context\n"
        "with this scene needs (rc_*_memory_requirements), the scene's bytes after\n"
        "commit, and the build (commit) time.\n"
        "Map formats: %s.\n", rcp_mesh_formats());
}

int rcp_cmd_info(int argc, char **argv)
{
    static const uint32_t all[] = {RC_BACKEND_BVH, RC_BACKEND_EMBREE, RC_BACKEND_VULKAN};
    const char *cmd = "info", *map = NULL;
    uint32_t backend = RC_BACKEND_AUTO, threads = 0, degenerate = 0, t;
    int only_one = 0, i, r, rc = RCP_EXIT_OK;
    size_t k;
    rcu_mesh mesh;
    float b[6];
    double t0, load_s;
    char n1[32], n2[32], n3[32];

    for (i = 1; i < argc; i++) {
        const char *v = NULL;
        if (rcp_is_help(argv[i])) {
            usage(stdout);
            return RCP_EXIT_OK;
        }
        if ((r = rcp_opt(argc, argv, &i, "--map", &v)) != 0) {
            if (r < 0) return RCP_EXIT_USAGE;
            map = v;
        } else if ((r = rcp_opt(argc, argv, &i, "--backend", &v)) != 0) {
            if (r < 0 || rcp_parse_backend(cmd, v, &backend) != 0) return RCP_EXIT_USAGE;
            only_one = 1;
        } else if ((r = rcp_opt_threads(cmd, argc, argv, &i, &threads)) != 0) {
            if (r < 0) return RCP_EXIT_USAGE;
        } else {
            return rcp_usage_error(cmd, "unknown argument '%s'", argv[i]);
        }
    }
    if (!map) return rcp_usage_error(cmd, "--map FILE is required");

    t0 = rcu_now();
    if (rcp_mesh_load(map, &mesh) != 0) return rcp_fail(cmd, "%s", rcu_last_error());
    load_s = rcu_now() - t0;
    rcu_mesh_bounds(&mesh, b);
    for (t = 0; t < mesh.triangle_count; t++) {
        const uint32_t *tri = mesh.indices + 3u * (size_t)t;
        const float *p0 = mesh.vertices + 3u * (size_t)tri[0], *p1 = mesh.vertices + 3u * (size_t)tri[1],
                    *p2 = mesh.vertices + 3u * (size_t)tri[2];
        double e1[3], e2[3], c[3];
        int q;
        for (q = 0; q < 3; q++) {
            e1[q] = (double)p1[q] - p0[q];
            e2[q] = (double)p2[q] - p0[q];
        }
        c[0] = e1[1] * e2[2] - e1[2] * e2[1];
        c[1] = e1[2] * e2[0] - e1[0] * e2[2];
        c[2] = e1[0] * e2[1] - e1[1] * e2[0];
        if (c[0] == 0.0 && c[1] == 0.0 && c[2] == 0.0) degenerate++;
    }
    printf("map         %s (loaded in %.3f s)\n", map, load_s);
    printf("triangles   %s (%s degenerate)\n", rcp_thousands(mesh.triangle_count, n1, sizeof n1),
           rcp_thousands(degenerate, n2, sizeof n2));
    printf("vertices    %s (%s as float32 + indices, referenced in place)\n",
           rcp_thousands(mesh.vertex_count, n1, sizeof n1),
           rcp_bytes((uint64_t)mesh.vertex_count * 12u + (uint64_t)mesh.triangle_count * 12u, n3, sizeof n3));
    printf("bounds      x %.3f .. %.3f, y %.3f .. %.3f, z %.3f .. %.3f m (size %.3f x %.3f x %.3f)\n",
           (double)b[0], (double)b[3], (double)b[1], (double)b[4], (double)b[2], (double)b[5],
           (double)(b[3] - b[0]), (double)(b[4] - b[1]), (double)(b[5] - b[2]));
    if (fmax(fmax(fabs(b[0]), fabs(b[3])), fmax(fmax(fabs(b[1]), fabs(b[4])), fmax(fabs(b[2]), fabs(b[5])))) > 1e4)
        printf("            (coordinates beyond 10 km: float32 resolution there is worse than 1 mm)\n");
    printf("\n%-8s %14s %14s %14s %10s %10s\n", "backend", "arena bytes", "scene bytes", "outside arena",
           "bytes/tri", "build s");
    for (k = 0; k < sizeof all / sizeof all[0]; k++) {
        rcp_world w;
        rc_scene_info si = rc_scene_info_default();
        rc_memory_stats ms = rc_memory_stats_default();
        uint32_t be = only_one ? backend : all[k];
        if (only_one && k > 0) break;
        if (be != RC_BACKEND_AUTO && !rc_backend_available(be)) continue;
        if (rcp_world_create(cmd, be, threads, &mesh, NULL, 0, &w) != RCP_EXIT_OK) {
            rc = RCP_EXIT_FAIL;
            continue;
        }
        rc_scene_get_info(w.scene, &si);
        rc_context_get_memory_stats(w.ctx, &ms);
        printf("%-8s %14s %14s %14s %10.1f %10.4f\n", rc_backend_name(w.backend),
               rcp_thousands(w.arena_bytes, n1, sizeof n1), rcp_thousands(si.bytes, n2, sizeof n2),
               rcp_thousands(ms.backend_bytes + ms.device_bytes, n3, sizeof n3),
               (double)(si.bytes + ms.backend_bytes + ms.device_bytes) / (double)mesh.triangle_count,
               w.build_s);
        rcp_world_destroy(&w);
    }
    if (rcp_baked_of(&mesh))
        printf("\n(a baked map of %s: the tree comes with it, so build s is rc_scene_load_baked, checks\n"
               "included, and the scene's bytes count the arena only; the map stays in its file.)\n",
               rcp_bytes(rcp_baked_of(&mesh)->bytes, n1, sizeof n1));
    printf("\narena bytes: rc_context_memory_requirements + rc_scene_memory_requirements (the peak,\n"
           "build scratch included); scene bytes: what the committed scene keeps in the arena\n"
           "(rc_scene_get_info); outside arena: what Embree/Vulkan hold themselves; bytes/tri:\n"
           "(scene + outside) per triangle; build s: rc_scene_commit.\n");
    rcu_mesh_free(&mesh);
    return rc;
}
