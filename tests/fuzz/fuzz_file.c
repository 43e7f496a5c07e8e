/* fz_input_file (fuzz_target.h). */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include "fuzz_target.h"

#include <unistd.h>

static char path[256];

/* a replay or fuzzing run leaves no file behind */
static void remove_input_file(void) { remove(path); }

const char *fz_input_file(const uint8_t *data, size_t size, const char *suffix)
{
    FILE *f;
    if (path[0] == '\0') {
        const char *dir = getenv("TMPDIR");
        snprintf(path, sizeof path, "%s/rc_fuzz_%ld%s", dir && dir[0] ? dir : "/tmp", (long)getpid(), suffix);
        atexit(remove_input_file);
    }
    f = fopen(path, "wb");
    if (f == NULL) return NULL;
    if (size > 0 && fwrite(data, 1, size, f) != size) {
        fclose(f);
        return NULL;
    }
    if (fclose(f) != 0) return NULL;
    return path;
}
