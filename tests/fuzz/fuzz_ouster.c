/* Fuzz target: the program's Ouster metadata reader (`--sensor ouster:FILE`:
 * cJSON, then rc_ouster_rays) on untrusted bytes. Promised: 0 or -1 with a
 * message, no read outside the text, no allocation the rays cannot need;
 * rays it returns are count = width x height, finite, with unit directions,
 * and the frame's column window inside the width. */
#include "fuzz_target.h"

#include <math.h>

#include "ouster_json.h"
#include "util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fz_input_file(data, size, ".json");
    rcp_rays rays;
    uint32_t i;
    if (path == NULL) return 0;
    if (rcp_ouster_load(path, &rays) != 0) {
        FZ_REQUIRE(rcu_last_error()[0] != '\0', "a failure says why");
        return 0;
    }
    FZ_REQUIRE(rays.count > 0 && rays.count == rays.width * rays.height, "count = width x height");
    FZ_REQUIRE(rays.window_start < rays.width && rays.window_end < rays.width, "the window inside the width");
    for (i = 0; i < rays.count; ++i) {
        const float *o = rays.origins + 3u * i, *d = rays.dirs + 3u * i;
        const double len = sqrt((double)d[0] * d[0] + (double)d[1] * d[1] + (double)d[2] * d[2]);
        FZ_REQUIRE(isfinite(o[0]) && isfinite(o[1]) && isfinite(o[2]), "finite origins");
        FZ_REQUIRE(fabs(len - 1.0) < 1e-5, "unit directions");
    }
    rcp_rays_free(&rays);
    return 0;
}
