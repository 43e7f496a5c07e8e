/* Fuzz target: rcutil's PLY reader (the program's own, for `rangecast
 * simulate`, `bench --map` and the tests) on untrusted bytes. Promised: it
 * returns 0 or -1 with a message, never reads outside the file or allocates
 * past what the file can hold; a mesh it returns has every index below its
 * vertex count. */
#include "fuzz_target.h"

#include "ply.h"
#include "util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fz_input_file(data, size, ".ply");
    rcu_mesh mesh = {0};
    uint64_t i;
    int rc;
    if (path == NULL) return 0;
    rc = rcu_mesh_read_ply(path, &mesh);
    FZ_REQUIRE(rc == 0 || rc == -1, "0 or -1");
    if (rc != 0) {
        FZ_REQUIRE(rcu_last_error()[0] != '\0', "a failure says why");
        return 0;
    }
    FZ_REQUIRE(mesh.triangle_count == 0 || (mesh.indices != NULL && mesh.vertices != NULL), "arrays for the counts");
    for (i = 0; i < (uint64_t)mesh.triangle_count * 3u; ++i)
        FZ_REQUIRE(mesh.indices[i] < mesh.vertex_count, "indices below the vertex count");
    rcu_mesh_free(&mesh);
    return 0;
}
