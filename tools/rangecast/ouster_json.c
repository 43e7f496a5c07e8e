#include "ouster_json.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util.h"

void rcp_rays_free(rcp_rays *rays)
{
    if (!rays) return;
    free(rays->origins);
    free(rays->dirs);
    free(rays->pixel_shift);
    memset(rays, 0, sizeof *rays);
}

rc_rays_desc rcp_rays_desc(const rcp_rays *rays)
{
    rc_rays_desc rd = rc_rays_desc_default();
    rd.common.range_min = rays->range_min;
    rd.common.range_max = rays->range_max;
    rd.directions = rays->dirs;
    rd.origins = rays->origins;
    rd.ray_count = rays->count;
    rd.width = rays->width;
    rd.height = rays->height;
    return rd;
}

#if defined(RANGECAST_WITH_CJSON)
#include <cJSON.h>

/* name in section (an object of root) when root has that section, else at
 * the top level (the legacy layout). */
static const cJSON *field(const cJSON *root, const char *section, const char *name)
{
    const cJSON *s = cJSON_GetObjectItemCaseSensitive(root, section);
    return cJSON_GetObjectItemCaseSensitive(cJSON_IsObject(s) ? s : root, name);
}

/* n finite numbers from a JSON array of exactly n (n 0: any length, set). */
static double *numbers(const cJSON *a, uint32_t *n)
{
    const cJSON *e;
    double *v;
    uint32_t k = 0, size;
    if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) <= 0) return NULL;
    size = (uint32_t)cJSON_GetArraySize(a);
    if (*n && size != *n) return NULL;
    v = (double *)malloc(sizeof(double) * size);
    if (!v) return NULL;
    cJSON_ArrayForEach(e, a) {
        if (!cJSON_IsNumber(e)) {
            free(v);
            return NULL;
        }
        v[k++] = e->valuedouble;
    }
    *n = size;
    return v;
}

/* The columns of a frame: lidar_data_format.columns_per_frame, else the
 * "1024" of lidar_mode "1024x10". 0 when neither is there. */
static uint32_t columns_of(const cJSON *root)
{
    const cJSON *c = field(root, "lidar_data_format", "columns_per_frame"), *m;
    if (!cJSON_IsNumber(c)) c = field(root, "data_format", "columns_per_frame");
    if (cJSON_IsNumber(c) && c->valuedouble >= 1 && c->valuedouble <= 65536) return (uint32_t)c->valuedouble;
    m = field(root, "config_params", "lidar_mode");
    if (cJSON_IsString(m)) {
        const long v = strtol(m->valuestring, NULL, 10);
        if (v >= 1 && v <= 65536 && strchr(m->valuestring, 'x')) return (uint32_t)v;
    }
    return 0;
}

/* lidar_data_format's name, else data_format's (older firmware). */
static const cJSON *format_field(const cJSON *root, const char *name)
{
    const cJSON *c = field(root, "lidar_data_format", name);
    return c ? c : field(root, "data_format", name);
}

/* pixel_shift_by_row and column_window into out (width and height set);
 * NULL, or what is wrong with them. */
static const char *frame_of(const cJSON *root, rcp_rays *out)
{
    const cJSON *shift = format_field(root, "pixel_shift_by_row"), *win = format_field(root, "column_window");
    out->window_start = 0;
    out->window_end = out->width - 1u;
    if (shift) {
        uint32_t n = out->height, u;
        double *v = numbers(shift, &n);
        if (!v) return "pixel_shift_by_row must be one integer a beam";
        out->pixel_shift = (int32_t *)malloc(sizeof(int32_t) * n);
        for (u = 0; out->pixel_shift && u < n; ++u) {
            /* the range first: casting a double out of int32_t's range is undefined */
            if (!(v[u] >= -65536.0 && v[u] <= 65536.0) || v[u] != (double)(int32_t)v[u]) {
                free(v);
                return "pixel_shift_by_row must be one integer a beam";
            }
            out->pixel_shift[u] = (int32_t)v[u];
        }
        free(v);
        if (!out->pixel_shift) return "out of memory for pixel_shift_by_row";
    }
    if (win) {
        uint32_t two = 2;
        double *v = numbers(win, &two);
        const int ok = v && v[0] >= 0 && v[1] >= 0 && v[0] < out->width && v[1] < out->width &&
                       v[0] == (double)(uint32_t)v[0] && v[1] == (double)(uint32_t)v[1];
        if (ok) {
            out->window_start = (uint32_t)v[0];
            out->window_end = (uint32_t)v[1];
        }
        free(v);
        if (!ok) return "column_window must be two column indices [start, end] below columns_per_frame";
    }
    return NULL;
}

int rcp_ouster_load(const char *path, rcp_rays *out)
{
    unsigned char *text = NULL;
    size_t size = 0;
    cJSON *root;
    rc_ouster_desc d = rc_ouster_desc_default();
    rc_rays_desc rd;
    double *alt = NULL, *azi = NULL, *m = NULL;
    uint32_t beams = 0, sixteen = 16;
    const cJSON *b2l, *l2s, *offset;
    const char *problem = NULL;
    rc_status st = RC_OK;
    memset(out, 0, sizeof *out);
    if (rcu_read_file(path, &text, &size) != 0) return -1; /* its message names the file */
    root = cJSON_Parse((const char *)text);
    free(text);
    if (!cJSON_IsObject(root)) {
        cJSON_Delete(root);
        return rcu_fail("%s: not a JSON object (Ouster metadata is one)", path);
    }
    alt = numbers(field(root, "beam_intrinsics", "beam_altitude_angles"), &beams);
    azi = numbers(field(root, "beam_intrinsics", "beam_azimuth_angles"), &beams);
    d.beams = beams;
    d.columns = columns_of(root);
    d.altitudes_deg = alt;
    d.azimuths_deg = azi;
    b2l = field(root, "beam_intrinsics", "beam_to_lidar_transform");
    offset = field(root, "beam_intrinsics", "lidar_origin_to_beam_origin_mm");
    l2s = field(root, "lidar_intrinsics", "lidar_to_sensor_transform");
    if (!alt || !azi) {
        problem = "beam_altitude_angles and beam_azimuth_angles must be two arrays of numbers of one length";
    } else if (d.columns == 0) {
        problem = "no columns_per_frame and no lidar_mode like \"1024x10\"";
    } else if (beams > RC_OUSTER_MAX_RAYS / d.columns) {
        /* before the arrays below: rc_ouster_rays would refuse them anyway */
        problem = "beams x columns_per_frame is more than 2^24 rays (RC_OUSTER_MAX_RAYS)";
    } else if (b2l && !(m = numbers(b2l, &sixteen))) {
        problem = "beam_to_lidar_transform must be 16 numbers (4x4, row by row)";
    } else {
        if (m) memcpy(d.beam_to_lidar, m, sizeof d.beam_to_lidar);
        else if (cJSON_IsNumber(offset)) d.beam_to_lidar[3] = offset->valuedouble;
        free(m);
        m = NULL;
        if (l2s && !(m = numbers(l2s, &sixteen)))
            problem = "lidar_to_sensor_transform must be 16 numbers (4x4, row by row)";
        else if (m)
            memcpy(d.lidar_to_sensor, m, sizeof d.lidar_to_sensor);
    }
    if (!problem) {
        const size_t n = (size_t)d.beams * d.columns;
        out->origins = (float *)malloc(sizeof(float) * 3u * n);
        out->dirs = (float *)malloc(sizeof(float) * 3u * n);
        if (!out->origins || !out->dirs) problem = "out of memory for its rays";
        else if ((st = rc_ouster_rays(&d, &rd, out->origins, out->dirs, NULL)) != RC_OK)
            problem = "rc_ouster_rays refused its values (a transform that is not rigid, a non-finite number, "
                      "a translation past 1e8 m, or more than 2^24 rays)";
    }
    if (!problem) {
        out->width = rd.width;
        out->height = rd.height;
        problem = frame_of(root, out);
    }
    free(alt);
    free(azi);
    free(m);
    cJSON_Delete(root);
    if (problem) {
        rcp_rays_free(out);
        return rcu_fail("%s: Ouster metadata: %s%s%s", path, problem, st != RC_OK ? ": " : "",
                        st != RC_OK ? rc_status_string(st) : "");
    }
    out->count = rd.ray_count;
    out->width = rd.width;
    out->height = rd.height;
    out->range_min = rd.common.range_min;
    out->range_max = rd.common.range_max;
    return 0;
}
#else
int rcp_ouster_load(const char *path, rcp_rays *out)
{
    memset(out, 0, sizeof *out);
    return rcu_fail("%s: this rangecast was built without cJSON (libcjson-dev), so it cannot read Ouster metadata",
                    path);
}
#endif
