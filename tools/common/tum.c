#include "tum.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "poses.h"
#include "util.h"

/* Skips spaces, tabs and commas (not line ends). */
static const char *skip_separators(const char *p)
{
    while (*p == ' ' || *p == '\t' || *p == ',') ++p;
    return p;
}

/* Parses one line's eight numbers into v; returns how many it found (9 for
 * more than eight), or -1 when something there is not a number. */
static int parse_line(const char *p, const char *end, double v[8])
{
    int n = 0;
    for (;;) {
        char *next;
        p = skip_separators(p);
        if (p >= end || *p == '\r') return n;
        if (n == 8) return 9;
        v[n] = strtod(p, &next);
        /* strtod reads past the line only through spaces it skips first;
         * skip_separators has taken those, so next stays on the line */
        if (next == p || next > end) return -1;
        ++n;
        p = next;
        if (p < end && *p != ' ' && *p != '\t' && *p != ',' && *p != '\r') return -1;
    }
}

int rcu_tum_read(const char *path, rc_pose **out, uint32_t *count)
{
    unsigned char *data;
    size_t size, lines = 1, i, n = 0, line = 0;
    const char *p, *end;
    rc_pose *poses;
    if (rcu_read_file(path, &data, &size) != 0) return -1;
    for (i = 0; i < size; ++i) lines += data[i] == '\n';
    if (lines > UINT32_MAX) lines = UINT32_MAX;
    if (lines > SIZE_MAX / sizeof *poses) {
        free(data);
        return rcu_fail("%s: too many lines (%zu)", path, lines);
    }
    poses = (rc_pose *)malloc(lines * sizeof *poses);
    if (!poses) {
        free(data);
        return rcu_fail("%s: out of memory for %zu poses", path, lines);
    }
    p = (const char *)data;
    end = p + size;
    while (p < end) {
        const char *eol = memchr(p, '\n', (size_t)(end - p));
        const char *first;
        double v[8], norm;
        int k, got;
        if (!eol) eol = end;
        ++line;
        first = skip_separators(p);
        if (first >= eol || *first == '#' || *first == '\r') {
            p = eol + 1;
            continue;
        }
        if (memchr(p, '\0', (size_t)(eol - p)) != NULL) {
            rcu_fail("%s:%zu: a NUL byte (is this a raw pose file? those end in .bin)", path, line);
            goto fail;
        }
        got = parse_line(first, eol, v);
        if (got < 0 || got > 8) {
            rcu_fail("%s:%zu: %s (expected 'timestamp x y z qx qy qz qw')", path, line,
                     got < 0 ? "not a number" : "more than 8 numbers");
            goto fail;
        }
        if (got != 8) {
            rcu_fail("%s:%zu: %d number%s (expected 8: timestamp x y z qx qy qz qw)", path, line, got,
                     got == 1 ? "" : "s");
            goto fail;
        }
        for (k = 0; k < 8; ++k)
            if (!isfinite(v[k]) || (k > 0 && fabs(v[k]) > FLT_MAX)) {
                rcu_fail("%s:%zu: value %d is not finite in float", path, line, k + 1);
                goto fail;
            }
        for (k = 0; k < 3; ++k) poses[n].position[k] = (float)v[1 + k];
        for (k = 0; k < 4; ++k) poses[n].orientation[k] = (float)v[4 + k];
        norm = rcu_pose_quaternion_norm(&poses[n]);
        if (fabs(norm - 1.0) > RCU_POSE_NORM_TOLERANCE) {
            rcu_fail("%s:%zu: quaternion (%g, %g, %g, %g) has norm %g, not 1 (the order is qx qy qz qw)", path,
                     line, v[4], v[5], v[6], v[7], norm);
            goto fail;
        }
        if (++n == UINT32_MAX) break;
        p = eol + 1;
    }
    free(data);
    if (n == 0) {
        free(poses);
        return rcu_fail("%s: no pose (expected lines 'timestamp x y z qx qy qz qw')", path);
    }
    *out = poses;
    *count = (uint32_t)n;
    return 0;
fail:
    free(data);
    free(poses);
    return -1;
}

int rcu_tum_write(const char *path, const rc_pose *poses, uint32_t count, double period)
{
    FILE *f = fopen(path, "wb");
    uint32_t i;
    if (!f) return rcu_fail("%s: %s", path, strerror(errno));
    fprintf(f, "# timestamp tx ty tz qx qy qz qw (base-to-map; written by rangecast)\n");
    for (i = 0; i < count; ++i) {
        const rc_pose *q = &poses[i];
        fprintf(f, "%.6f %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", (double)i * period, (double)q->position[0],
                (double)q->position[1], (double)q->position[2], (double)q->orientation[0],
                (double)q->orientation[1], (double)q->orientation[2], (double)q->orientation[3]);
    }
    i = ferror(f) != 0;
    if (fclose(f) != 0 || i) {
        rcu_remove_partial(path);
        return rcu_fail("%s: write error", path);
    }
    return 0;
}
