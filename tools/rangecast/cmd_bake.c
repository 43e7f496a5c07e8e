/* rangecast bake: a map built once on the built-in backend and written as a
 * baked map (rc_scene_bake) that robots load in place with no build. The
 * written file is loaded back and checked before the command reports
 * success. */
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
        "Usage: rangecast bake --map FILE --out FILE.rcmap [--threads N]\n"
        "\n"
        "Builds the map's BVH on the built-in backend (N threads; 0 = all cores) and\n"
        "writes the mesh and its tree as a baked map: one relocatable, checksummed file\n"
        "that rc_scene_load_baked uses in place (mmap it, or keep it in flash) with no\n"
        "parsing and no build, giving the same ranges bit for bit. The file is written\n"
        "through a temporary file and renamed into place, then read back and loaded\n"
        "once (checksum and structure) before the summary is printed. The format is\n"
        "docs/baked-map.md; every rangecast command reads .rcmap maps too.\n"
        "Map formats: %s.\n", rcp_mesh_formats());
}

int rcp_cmd_bake(int argc, char **argv)
{
    const char *cmd = "bake", *map = NULL, *out = NULL;
    uint32_t threads = 0;
    int i, r;
    rcu_mesh mesh, back;
    rcp_world w, check;
    size_t bytes = 0;
    void *blob;
    rc_status st;
    char n1[32], n2[32];

    for (i = 1; i < argc; i++) {
        const char *v = NULL;
        if (rcp_is_help(argv[i])) {
            usage(stdout);
            return RCP_EXIT_OK;
        }
        if ((r = rcp_opt(argc, argv, &i, "--map", &v)) != 0) {
            if (r < 0) return RCP_EXIT_USAGE;
            map = v;
        } else if ((r = rcp_opt(argc, argv, &i, "--out", &v)) != 0) {
            if (r < 0) return RCP_EXIT_USAGE;
            out = v;
        } else if ((r = rcp_opt_threads(cmd, argc, argv, &i, &threads)) != 0) {
            if (r < 0) return RCP_EXIT_USAGE;
        } else {
            return rcp_usage_error(cmd, "unknown argument '%s'", argv[i]);
        }
    }
    if (!map) return rcp_usage_error(cmd, "--map FILE is required");
    if (!out) return rcp_usage_error(cmd, "--out FILE.rcmap is required");
    {
        char ext[16];
        rcu_path_extension(out, ext, sizeof ext);
        if (strcmp(ext, "rcmap") != 0)
            return rcp_usage_error(cmd, "--out: '%s' should end in .rcmap (the extension the program reads maps by)", out);
    }

    if (rcp_mesh_load(map, &mesh) != 0) return rcp_fail(cmd, "%s", rcu_last_error());
    if (rcp_world_create(cmd, RC_BACKEND_BVH, threads, &mesh, NULL, 0, &w) != RCP_EXIT_OK) {
        rcu_mesh_free(&mesh);
        return RCP_EXIT_FAIL;
    }
    st = rc_scene_bake(w.scene, NULL, 0, &bytes);
    blob = st == RC_OK ? malloc(bytes) : NULL;
    if (st == RC_OK && blob == NULL) st = RC_ERR_OUT_OF_MEMORY;
    if (st == RC_OK) st = rc_scene_bake(w.scene, blob, bytes, &bytes);
    if (st != RC_OK) {
        rcp_lib_error(cmd, w.ctx, "rc_scene_bake", st);
        free(blob);
        rcp_world_destroy(&w);
        rcu_mesh_free(&mesh);
        return RCP_EXIT_FAIL;
    }
    r = rcp_baked_write(out, blob, bytes);
    free(blob);
    if (r != 0) {
        rcp_world_destroy(&w);
        rcu_mesh_free(&mesh);
        return rcp_fail(cmd, "%s", rcu_last_error());
    }
    /* what a robot will do: map the file and load it */
    if (rcp_mesh_load(out, &back) != 0) {
        remove(out);
        rcp_world_destroy(&w);
        rcu_mesh_free(&mesh);
        return rcp_fail(cmd, "reading back %s: %s (removed it)", out, rcu_last_error());
    }
    r = rcp_world_create(cmd, RC_BACKEND_BVH, threads, &back, NULL, 0, &check);
    if (r != RCP_EXIT_OK) {
        remove(out);
        fprintf(stderr, "rangecast %s: %s did not load back; removed it\n", cmd, out);
    } else {
        printf("%s: %s triangles, %s (%.1f bytes a triangle)\n", out, rcp_thousands(mesh.triangle_count, n1, sizeof n1),
               rcp_bytes(bytes, n2, sizeof n2), (double)bytes / (double)mesh.triangle_count);
        printf("built in %.3f s; loads in %.3f s (checksum and structure checked, no build)\n", w.build_s,
               check.build_s);
        rcp_world_destroy(&check);
    }
    rcp_world_destroy(&w);
    rcu_mesh_free(&back);
    rcu_mesh_free(&mesh);
    return r;
}
