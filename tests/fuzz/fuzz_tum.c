/* Fuzz target: rcutil's TUM trajectory reader (tum.h: `--poses FILE.tum` of
 * `rangecast simulate` and `bench`) on untrusted bytes. Promised: it returns
 * 0 or -1 with a message, never reads outside the file; poses it returns
 * are at least one, every value finite and every quaternion within 1e-3 of
 * unit length, and a failure hands nothing back. */
#include "fuzz_target.h"

#include <math.h>

#include "poses.h"
#include "util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fz_input_file(data, size, ".tum");
    rc_pose *poses = NULL;
    uint32_t count = 0, i;
    int rc, k;
    if (path == NULL) return 0;
    rc = rcu_poses_read(path, &poses, &count);
    FZ_REQUIRE(rc == 0 || rc == -1, "0 or -1");
    if (rc != 0) {
        FZ_REQUIRE(rcu_last_error()[0] != '\0', "a failure says why");
        FZ_REQUIRE(poses == NULL && count == 0, "a failure hands nothing back");
        return 0;
    }
    FZ_REQUIRE(count >= 1 && poses != NULL, "at least one pose");
    for (i = 0; i < count; ++i) {
        double norm2 = 0.0;
        for (k = 0; k < 3; ++k) FZ_REQUIRE(isfinite(poses[i].position[k]), "a finite position");
        for (k = 0; k < 4; ++k) norm2 += (double)poses[i].orientation[k] * poses[i].orientation[k];
        FZ_REQUIRE(fabs(sqrt(norm2) - 1.0) <= 1e-3 + 1e-6, "a unit quaternion");
    }
    free(poses);
    return 0;
}
