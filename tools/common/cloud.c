#include "cloud.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "reference.h"

void rcu_cloud_init(rcu_cloud *cloud, uint32_t fields)
{
    memset(cloud, 0, sizeof *cloud);
    cloud->fields = fields;
}

void rcu_cloud_free(rcu_cloud *cloud)
{
    if (!cloud) return;
    free(cloud->xyz);
    free(cloud->range);
    free(cloud->intensity);
    free(cloud->ring);
    rcu_cloud_init(cloud, cloud->fields);
}

static int cloud_reserve(rcu_cloud *c, size_t need)
{
    size_t cap = c->capacity;
    void *p;
    if (need <= cap) return 0;
    while (cap < need) cap = cap ? cap * 2 : 4096;
    if (!(p = realloc(c->xyz, cap * 3u * sizeof(float)))) goto oom;
    c->xyz = (float *)p;
    if (c->fields & RCU_CLOUD_RANGE) {
        if (!(p = realloc(c->range, cap * sizeof(float)))) goto oom;
        c->range = (float *)p;
    }
    if (c->fields & RCU_CLOUD_INTENSITY) {
        if (!(p = realloc(c->intensity, cap * sizeof(float)))) goto oom;
        c->intensity = (float *)p;
    }
    if (c->fields & RCU_CLOUD_RING) {
        if (!(p = realloc(c->ring, cap * sizeof(uint16_t)))) goto oom;
        c->ring = (uint16_t *)p;
    }
    c->capacity = cap;
    return 0;
oom:
    return rcu_fail("out of memory for a cloud of %zu points", need);
}

/* A valid return: the hit flag, or without hits a finite point. */
static int is_return(const rcu_scan_view *v, size_t k)
{
    const float *p = v->points + 3u * k;
    return v->hits ? v->hits[k] != 0 : (isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]));
}

int rcu_cloud_append(rcu_cloud *cloud, const rcu_scan_view *v)
{
    uint32_t s, r, columns = v->columns ? v->columns : v->rays_per_scan;
    rcu_xform mount, to_map;
    rc_pose identity = rc_pose_identity();
    rcu_xform_from_pose(v->sensor_to_base ? v->sensor_to_base : &identity, &mount);
    for (s = 0; s < v->pose_count; s++) {
        size_t base = (size_t)s * v->rays_per_scan, valid = 0;
        if (v->poses) {
            rcu_xform pose;
            rcu_xform_from_pose(&v->poses[s], &pose);
            rcu_xform_mul(&pose, &mount, &to_map);
        }
        for (r = 0; r < v->rays_per_scan; r++) valid += (size_t)is_return(v, base + r);
        if (cloud_reserve(cloud, cloud->count + valid) != 0) return -1;
        for (r = 0; r < v->rays_per_scan; r++) {
            const float *p = v->points + 3u * (base + r);
            float *out = cloud->xyz + 3u * cloud->count;
            double pd[3], len;
            if (!is_return(v, base + r)) continue;
            pd[0] = p[0];
            pd[1] = p[1];
            pd[2] = p[2];
            len = sqrt(pd[0] * pd[0] + pd[1] * pd[1] + pd[2] * pd[2]);
            if (v->poses) rcu_xform_point(&to_map, pd, pd);
            out[0] = (float)pd[0];
            out[1] = (float)pd[1];
            out[2] = (float)pd[2];
            if (cloud->fields & RCU_CLOUD_RANGE)
                cloud->range[cloud->count] = v->ranges ? v->ranges[base + r] : (float)len;
            if (cloud->fields & RCU_CLOUD_INTENSITY) {
                float in = 1.0f;
                if (v->normals && len > 0.0) {
                    const float *n = v->normals + 3u * (base + r);
                    in = (float)fabs(((double)n[0] * p[0] + (double)n[1] * p[1] + (double)n[2] * p[2]) / len);
                }
                cloud->intensity[cloud->count] = in;
            }
            if (cloud->fields & RCU_CLOUD_RING)
                cloud->ring[cloud->count] = (uint16_t)(r / columns);
            cloud->count++;
        }
    }
    return 0;
}

/* The optional fields, in file order. */
static const struct {
    uint32_t flag;
    const char *name;
    const char *ply_type;
    char pcd_type;
    int size;
} extra_fields[] = {{RCU_CLOUD_RANGE, "range", "float", 'F', 4},
                    {RCU_CLOUD_INTENSITY, "intensity", "float", 'F', 4},
                    {RCU_CLOUD_RING, "ring", "ushort", 'U', 2}};
#define N_EXTRA 3

static size_t record_size(uint32_t fields)
{
    size_t n = 12;
    int k;
    for (k = 0; k < N_EXTRA; k++)
        if (fields & extra_fields[k].flag) n += (size_t)extra_fields[k].size;
    return n;
}

static void pack_record(const rcu_cloud *c, size_t i, unsigned char *rec)
{
    rcu_store_f32le(rec, c->xyz[3u * i]);
    rcu_store_f32le(rec + 4, c->xyz[3u * i + 1]);
    rcu_store_f32le(rec + 8, c->xyz[3u * i + 2]);
    rec += 12;
    if (c->fields & RCU_CLOUD_RANGE) {
        rcu_store_f32le(rec, c->range[i]);
        rec += 4;
    }
    if (c->fields & RCU_CLOUD_INTENSITY) {
        rcu_store_f32le(rec, c->intensity[i]);
        rec += 4;
    }
    if (c->fields & RCU_CLOUD_RING) rcu_store_le16(rec, c->ring[i]);
}

static void print_record(FILE *f, const rcu_cloud *c, size_t i)
{
    fprintf(f, "%.9g %.9g %.9g", (double)c->xyz[3u * i], (double)c->xyz[3u * i + 1],
            (double)c->xyz[3u * i + 2]);
    if (c->fields & RCU_CLOUD_RANGE) fprintf(f, " %.9g", (double)c->range[i]);
    if (c->fields & RCU_CLOUD_INTENSITY) fprintf(f, " %.6g", (double)c->intensity[i]);
    if (c->fields & RCU_CLOUD_RING) fprintf(f, " %u", (unsigned)c->ring[i]);
    fputc('\n', f);
}

static int write_body(FILE *f, const rcu_cloud *c, int ascii)
{
    size_t i;
    if (ascii) {
        for (i = 0; i < c->count; i++) print_record(f, c, i);
    } else {
        enum { CHUNK = 4096 };
        size_t rs = record_size(c->fields), n, j;
        unsigned char *buf = (unsigned char *)malloc(CHUNK * rs);
        if (!buf) return -1;
        for (i = 0; i < c->count; i += n) {
            n = c->count - i < CHUNK ? c->count - i : CHUNK;
            for (j = 0; j < n; j++) pack_record(c, i + j, buf + j * rs);
            if (fwrite(buf, rs, n, f) != n) {
                free(buf);
                return -1;
            }
        }
        free(buf);
    }
    return ferror(f) ? -1 : 0;
}

/* Closes f; on any error removes the half-written file. */
static int finish(FILE *f, const char *path, int st)
{
    if (fclose(f) != 0) st = -1;
    if (st == 0) return 0;
    rcu_remove_partial(path);
    return rcu_fail("%s: write error", path);
}

static void write_ply_header(FILE *f, uint32_t fields, size_t count, int ascii)
{
    int k;
    fprintf(f, "ply\nformat %s 1.0\ncomment written by rangecast\nelement vertex %zu\n"
               "property float x\nproperty float y\nproperty float z\n",
            ascii ? "ascii" : "binary_little_endian", count);
    for (k = 0; k < N_EXTRA; k++)
        if (fields & extra_fields[k].flag) fprintf(f, "property %s %s\n", extra_fields[k].ply_type, extra_fields[k].name);
    fprintf(f, "end_header\n");
}

static void write_pcd_header(FILE *f, uint32_t fields, size_t count, int ascii)
{
    int k;
    fprintf(f, "# .PCD v0.7 - Point Cloud Data file format (written by rangecast)\nVERSION 0.7\nFIELDS x y z");
    for (k = 0; k < N_EXTRA; k++)
        if (fields & extra_fields[k].flag) fprintf(f, " %s", extra_fields[k].name);
    fprintf(f, "\nSIZE 4 4 4");
    for (k = 0; k < N_EXTRA; k++)
        if (fields & extra_fields[k].flag) fprintf(f, " %d", extra_fields[k].size);
    fprintf(f, "\nTYPE F F F");
    for (k = 0; k < N_EXTRA; k++)
        if (fields & extra_fields[k].flag) fprintf(f, " %c", extra_fields[k].pcd_type);
    fprintf(f, "\nCOUNT 1 1 1");
    for (k = 0; k < N_EXTRA; k++)
        if (fields & extra_fields[k].flag) fprintf(f, " 1");
    fprintf(f, "\nWIDTH %zu\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS %zu\nDATA %s\n", count, count,
            ascii ? "ascii" : "binary");
}

int rcu_cloud_write_ply(const char *path, const rcu_cloud *c, int ascii)
{
    FILE *f = fopen(path, "wb");
    if (!f) return rcu_fail("%s: %s", path, strerror(errno));
    write_ply_header(f, c->fields, c->count, ascii);
    return finish(f, path, write_body(f, c, ascii));
}

int rcu_cloud_write_pcd(const char *path, const rcu_cloud *c, int ascii)
{
    FILE *f = fopen(path, "wb");
    if (!f) return rcu_fail("%s: %s", path, strerror(errno));
    write_pcd_header(f, c->fields, c->count, ascii);
    return finish(f, path, write_body(f, c, ascii));
}

int rcu_cloud_write(const char *path, const rcu_cloud *cloud, int ascii)
{
    char ext[8];
    rcu_path_extension(path, ext, sizeof ext);
    if (strcmp(ext, "ply") == 0) return rcu_cloud_write_ply(path, cloud, ascii);
    if (strcmp(ext, "pcd") == 0) return rcu_cloud_write_pcd(path, cloud, ascii);
    return rcu_fail("%s: unknown point cloud format '.%s' (use .ply or .pcd)", path, ext);
}

/* Streaming (cloud.h). The latest batch is held in memory, the ones before
 * it went to the body: a stream of one batch (a cloud that fits one call)
 * is written straight to the output at close, with no body and no copy. */

/* Frees what s holds and closes its files (the body is removed; the output
 * removed too unless keep). */
static void stream_release(rcu_cloud_stream *s, int keep)
{
    if (s->body) fclose(s->body);
    if (s->body && s->body_path) remove(s->body_path);
    if (s->out) fclose(s->out);
    if (s->path && !keep) rcu_remove_partial(s->path);
    free(s->path);
    free(s->body_path);
    rcu_cloud_free(&s->batch);
    memset(s, 0, sizeof *s);
}

int rcu_cloud_stream_open(rcu_cloud_stream *s, const char *path, uint32_t fields, int ascii)
{
    char ext[8];
    size_t len = strlen(path);
    memset(s, 0, sizeof *s);
    rcu_path_extension(path, ext, sizeof ext);
    if (strcmp(ext, "ply") != 0 && strcmp(ext, "pcd") != 0)
        return rcu_fail("%s: unknown point cloud format '.%s' (use .ply or .pcd)", path, ext);
    s->pcd = strcmp(ext, "pcd") == 0;
    s->ascii = ascii;
    rcu_cloud_init(&s->batch, fields);
    s->path = (char *)malloc(len + 1u);
    s->body_path = (char *)malloc(len + sizeof ".body.partial");
    if (!s->path || !s->body_path) {
        stream_release(s, 1);
        return rcu_fail("out of memory");
    }
    memcpy(s->path, path, len + 1u);
    memcpy(s->body_path, path, len);
    memcpy(s->body_path + len, ".body.partial", sizeof ".body.partial");
    /* the output is opened now, so that a path it cannot take fails
     * before the work, not after it */
    if (!(s->out = fopen(path, "wb"))) {
        const int e = errno;
        stream_release(s, 1); /* not ours to remove: a file there stays */
        return rcu_fail("%s: %s", path, strerror(e));
    }
    return 0;
}

/* The held batch to the body (opened at the first). */
static int stream_flush(rcu_cloud_stream *s)
{
    if (s->batch.count == 0) return 0;
    if (!s->body && !(s->body = fopen(s->body_path, "w+b"))) return rcu_fail("%s: %s", s->body_path, strerror(errno));
    if (write_body(s->body, &s->batch, s->ascii) != 0) return rcu_fail("%s: write error", s->path);
    s->batch.count = 0;
    return 0;
}

int rcu_cloud_stream_append(rcu_cloud_stream *s, const rcu_scan_view *view)
{
    if (stream_flush(s) != 0) return -1;
    if (rcu_cloud_append(&s->batch, view) != 0) {
        s->batch.count = 0;
        return -1;
    }
    s->count += s->batch.count;
    return 0;
}

void rcu_cloud_stream_abort(rcu_cloud_stream *s) { stream_release(s, 0); }

int rcu_cloud_stream_close(rcu_cloud_stream *s)
{
    int st = 0;
    if (s->pcd)
        write_pcd_header(s->out, s->batch.fields, s->count, s->ascii);
    else
        write_ply_header(s->out, s->batch.fields, s->count, s->ascii);
    if (s->body) {
        enum { COPY = 1 << 20 };
        unsigned char *buf = (unsigned char *)malloc(COPY);
        size_t n;
        st = buf && stream_flush(s) == 0 && fflush(s->body) == 0 && fseek(s->body, 0L, SEEK_SET) == 0 ? 0 : -1;
        while (st == 0 && (n = fread(buf, 1, COPY, s->body)) > 0)
            if (fwrite(buf, 1, n, s->out) != n) st = -1;
        if (ferror(s->body)) st = -1;
        free(buf);
    } else {
        st = write_body(s->out, &s->batch, s->ascii);
    }
    if (ferror(s->out)) st = -1;
    if (fclose(s->out) != 0) st = -1;
    s->out = NULL;
    if (st != 0) {
        rcu_fail("%s: write error", s->path);
        stream_release(s, 0);
        return -1;
    }
    stream_release(s, 1);
    return 0;
}
