#include "ply.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { PLY_ASCII, PLY_LE, PLY_BE };
enum { T_NONE, T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64 };

#define PLY_MAX_PROPS 32
#define PLY_MAX_ELEMS 16

typedef struct ply_prop {
    char name[64];
    int type;        /* value type, or the index type of a list */
    int count_type;  /* T_NONE for a scalar */
} ply_prop;

typedef struct ply_elem {
    char name[64];
    uint64_t count;
    int nprops;
    ply_prop props[PLY_MAX_PROPS];
} ply_elem;

typedef struct ply_reader {
    const char *path;
    const unsigned char *start, *p, *end;
    int format;
} ply_reader;

static int type_from_name(const char *s)
{
    static const struct { const char *name; int type; } names[] = {
        {"char", T_I8},   {"int8", T_I8},     {"uchar", T_U8},   {"uint8", T_U8},
        {"short", T_I16}, {"int16", T_I16},   {"ushort", T_U16}, {"uint16", T_U16},
        {"int", T_I32},   {"int32", T_I32},   {"uint", T_U32},   {"uint32", T_U32},
        {"float", T_F32}, {"float32", T_F32}, {"double", T_F64}, {"float64", T_F64}};
    size_t i;
    for (i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strcmp(s, names[i].name) == 0) return names[i].type;
    return T_NONE;
}

static size_t type_size(int t)
{
    switch (t) {
    case T_I8: case T_U8: return 1;
    case T_I16: case T_U16: return 2;
    case T_I32: case T_U32: case T_F32: return 4;
    default: return 8;
    }
}

/* Reads one value as double (exact for every integer type and for float). */
static int read_value(ply_reader *r, int type, double *v)
{
    if (r->format == PLY_ASCII) {
        char *endp;
        while (r->p < r->end && (*r->p == ' ' || *r->p == '\t' || *r->p == '\n' || *r->p == '\r'))
            r->p++;
        if (r->p >= r->end) return rcu_fail("%s: ascii data ends early", r->path);
        *v = strtod((const char *)r->p, &endp);
        if ((const unsigned char *)endp == r->p)
            return rcu_fail("%s: bad number in ascii data near byte %ld", r->path,
                            (long)(r->p - r->start));
        r->p = (const unsigned char *)endp;
        return 0;
    } else {
        size_t n = type_size(type), i;
        unsigned char b[8];
        if ((size_t)(r->end - r->p) < n) return rcu_fail("%s: binary data ends early (truncated file?)", r->path);
        for (i = 0; i < n; i++) b[i] = r->p[r->format == PLY_LE ? i : n - 1 - i]; /* to little-endian */
        r->p += n;
        switch (type) {
        case T_I8: *v = (double)(int8_t)b[0]; break;
        case T_U8: *v = (double)b[0]; break;
        case T_I16: *v = (double)(int16_t)(uint16_t)(b[0] | (b[1] << 8)); break;
        case T_U16: *v = (double)(uint16_t)(b[0] | (b[1] << 8)); break;
        case T_I32: *v = (double)(int32_t)rcu_load_le32(b); break;
        case T_U32: *v = (double)rcu_load_le32(b); break;
        case T_F32: *v = (double)rcu_load_f32le(b); break;
        default: {
            uint64_t u = (uint64_t)rcu_load_le32(b) | ((uint64_t)rcu_load_le32(b + 4) << 32);
            double d;
            memcpy(&d, &u, 8);
            *v = d;
        }
        }
        return 0;
    }
}

/* Next header line into buf (without the line end); 0 when found. */
static int header_line(ply_reader *r, char *buf, size_t size)
{
    size_t n = 0;
    if (r->p >= r->end) return rcu_fail("%s: PLY header has no end_header", r->path);
    while (r->p < r->end && *r->p != '\n') {
        if (n + 1 < size && *r->p != '\r') buf[n++] = (char)*r->p;
        r->p++;
    }
    if (r->p < r->end) r->p++;
    buf[n] = 0;
    return 0;
}

static int parse_header(ply_reader *r, ply_elem *elems, int *nelems)
{
    char line[512], a[64], b[64], c[64], d[64];
    int have_format = 0;
    *nelems = 0;
    if (r->end - r->p < 4 || memcmp(r->p, "ply", 3) != 0 || (r->p[3] != '\n' && r->p[3] != '\r'))
        return rcu_fail("%s: not a PLY file (no 'ply' magic)", r->path);
    header_line(r, line, sizeof line);
    for (;;) {
        int n;
        if (header_line(r, line, sizeof line) != 0) return -1;
        n = sscanf(line, "%63s %63s %63s %63s", a, b, c, d);
        if (n <= 0) continue;
        if (strcmp(a, "end_header") == 0) break;
        if (strcmp(a, "comment") == 0 || strcmp(a, "obj_info") == 0) continue;
        if (strcmp(a, "format") == 0 && n >= 2) {
            if (strcmp(b, "ascii") == 0) r->format = PLY_ASCII;
            else if (strcmp(b, "binary_little_endian") == 0) r->format = PLY_LE;
            else if (strcmp(b, "binary_big_endian") == 0) r->format = PLY_BE;
            else return rcu_fail("%s: unknown PLY format '%s'", r->path, b);
            have_format = 1;
        } else if (strcmp(a, "element") == 0 && n >= 3) {
            ply_elem *e;
            char *endp;
            if (*nelems >= PLY_MAX_ELEMS) return rcu_fail("%s: too many PLY elements", r->path);
            e = &elems[(*nelems)++];
            memset(e, 0, sizeof *e);
            strcpy(e->name, b);
            /* digits only: strtoull would take "-3" as 2^64 - 3 */
            errno = 0;
            e->count = strtoull(c, &endp, 10);
            if (c[0] < '0' || c[0] > '9' || *endp || errno == ERANGE)
                return rcu_fail("%s: bad element count '%s'", r->path, c);
        } else if (strcmp(a, "property") == 0 && n >= 3) {
            ply_elem *e = *nelems ? &elems[*nelems - 1] : NULL;
            ply_prop *pr;
            if (!e) return rcu_fail("%s: property before any element", r->path);
            if (e->nprops >= PLY_MAX_PROPS) return rcu_fail("%s: too many properties", r->path);
            pr = &e->props[e->nprops++];
            memset(pr, 0, sizeof *pr);
            if (strcmp(b, "list") == 0) {
                if (n < 4) return rcu_fail("%s: bad list property '%s'", r->path, line);
                pr->count_type = type_from_name(c);
                pr->type = type_from_name(d);
                if (sscanf(line, "%*s %*s %*s %*s %63s", pr->name) != 1)
                    return rcu_fail("%s: list property without a name", r->path);
                if (pr->count_type == T_NONE || pr->type == T_NONE)
                    return rcu_fail("%s: unknown type in '%s'", r->path, line);
            } else {
                pr->type = type_from_name(b);
                strcpy(pr->name, c);
                if (pr->type == T_NONE) return rcu_fail("%s: unknown type '%s'", r->path, b);
            }
        } else {
            return rcu_fail("%s: unexpected PLY header line '%s'", r->path, line);
        }
    }
    if (!have_format) return rcu_fail("%s: PLY header has no format line", r->path);
    return 0;
}

static int grow_triangles(rcu_mesh *m, uint64_t *cap, uint64_t need)
{
    uint32_t *t;
    uint64_t c = *cap;
    if (need <= c) return 0;
    while (c < need) c = c ? c * 2 : 1024;
    if (c > UINT32_MAX) c = UINT32_MAX;
    if (need > c) return rcu_fail("more than 2^32 triangles");
    t = (uint32_t *)realloc(m->indices, (size_t)c * 3u * sizeof(uint32_t));
    if (!t) return rcu_fail("out of memory for %llu triangles", (unsigned long long)c);
    m->indices = t;
    *cap = c;
    return 0;
}

static int read_body(ply_reader *r, ply_elem *elems, int nelems, rcu_mesh *m)
{
    int ei, have_vertices = 0;
    uint64_t tri_cap = 0;
    for (ei = 0; ei < nelems; ei++) {
        ply_elem *e = &elems[ei];
        int is_vertex = strcmp(e->name, "vertex") == 0;
        int is_face = strcmp(e->name, "face") == 0;
        int xyz[3] = {-1, -1, -1}, list = -1, k;
        uint64_t i, min_bytes = 0;
        /* every instance takes at least this many bytes (ascii: 2 a value):
         * a count the file cannot hold is corrupt, not a reason to allocate */
        for (k = 0; k < e->nprops; k++)
            min_bytes += r->format == PLY_ASCII ? 2u : type_size(e->props[k].count_type != T_NONE
                                                                     ? e->props[k].count_type
                                                                     : e->props[k].type);
        if (min_bytes > 0 && e->count > (uint64_t)(r->end - r->p) / min_bytes)
            return rcu_fail("%s: element %s claims %llu entries, more than the file holds", r->path,
                            e->name, (unsigned long long)e->count);
        if (is_vertex) {
            /* a second one would replace the vertices under the faces read so far */
            if (have_vertices) return rcu_fail("%s: more than one vertex element", r->path);
            for (k = 0; k < e->nprops; k++) {
                if (e->props[k].count_type != T_NONE) continue;
                if (strcmp(e->props[k].name, "x") == 0) xyz[0] = k;
                if (strcmp(e->props[k].name, "y") == 0) xyz[1] = k;
                if (strcmp(e->props[k].name, "z") == 0) xyz[2] = k;
            }
            if (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0)
                return rcu_fail("%s: vertex element lacks x, y or z", r->path);
            if (e->count > UINT32_MAX) return rcu_fail("%s: more than 2^32 vertices", r->path);
            m->vertices = (float *)malloc((size_t)(e->count ? e->count : 1) * 3u * sizeof(float));
            if (!m->vertices) return rcu_fail("%s: out of memory for %llu vertices", r->path,
                                              (unsigned long long)e->count);
            have_vertices = 1;
        }
        if (is_face) {
            for (k = 0; k < e->nprops; k++)
                if (e->props[k].count_type != T_NONE &&
                    (strcmp(e->props[k].name, "vertex_indices") == 0 ||
                     strcmp(e->props[k].name, "vertex_index") == 0))
                    list = k;
            for (k = 0; k < e->nprops && list < 0; k++)
                if (e->props[k].count_type != T_NONE) list = k;
            if (list < 0) return rcu_fail("%s: face element has no list property", r->path);
            if (!have_vertices) return rcu_fail("%s: face element before the vertex element", r->path);
            if (grow_triangles(m, &tri_cap, e->count) != 0) return -1;
        }
        /* an element without properties has nothing to read, however many it claims */
        for (i = 0; e->nprops > 0 && i < e->count; i++) {
            for (k = 0; k < e->nprops; k++) {
                const ply_prop *pr = &e->props[k];
                double v;
                if (pr->count_type == T_NONE) {
                    if (read_value(r, pr->type, &v) != 0) return -1;
                    if (is_vertex) {
                        if (k == xyz[0]) m->vertices[3u * i] = (float)v;
                        else if (k == xyz[1]) m->vertices[3u * i + 1] = (float)v;
                        else if (k == xyz[2]) m->vertices[3u * i + 2] = (float)v;
                    }
                } else {
                    double cnt;
                    uint64_t n, j;
                    uint32_t first = 0, prev = 0;
                    if (read_value(r, pr->count_type, &cnt) != 0) return -1;
                    if (!(cnt >= 0.0) || cnt > 1e6 || cnt != floor(cnt))
                        return rcu_fail("%s: bad list length %g in element %s %llu", r->path, cnt,
                                        e->name, (unsigned long long)i);
                    n = (uint64_t)cnt;
                    for (j = 0; j < n; j++) {
                        uint32_t idx;
                        if (read_value(r, pr->type, &v) != 0) return -1;
                        if (!is_face || k != list) continue;
                        if (!(v >= 0.0) || v >= (double)m->vertex_count || v != floor(v))
                            return rcu_fail("%s: face %llu has vertex index %.0f, but there are %u "
                                            "vertices", r->path, (unsigned long long)i, v,
                                            m->vertex_count);
                        idx = (uint32_t)v;
                        if (j == 0) first = idx;
                        else if (j >= 2) {
                            uint32_t *t;
                            if (grow_triangles(m, &tri_cap, (uint64_t)m->triangle_count + 1) != 0)
                                return -1;
                            t = m->indices + 3u * (size_t)m->triangle_count++;
                            t[0] = first;
                            t[1] = prev;
                            t[2] = idx;
                        }
                        prev = idx;
                    }
                }
            }
            if (is_vertex) m->vertex_count = (uint32_t)(i + 1);
        }
    }
    if (!have_vertices) return rcu_fail("%s: no vertex element", r->path);
    if (m->triangle_count == 0) return rcu_fail("%s: no triangles (no face element, or only faces "
                                                "with fewer than 3 vertices)", r->path);
    return 0;
}

int rcu_mesh_read_ply(const char *path, rcu_mesh *out)
{
    unsigned char *data;
    size_t size;
    ply_reader r;
    ply_elem elems[PLY_MAX_ELEMS];
    int nelems, st;
    memset(out, 0, sizeof *out);
    if (rcu_read_file(path, &data, &size) != 0) return -1;
    r.path = path;
    r.start = r.p = data;
    r.end = data + size;
    r.format = PLY_ASCII;
    st = parse_header(&r, elems, &nelems);
    if (st == 0) st = read_body(&r, elems, nelems, out);
    free(data);
    if (st != 0) {
        rcu_mesh_free(out);
        return -1;
    }
    return 0;
}

int rcu_mesh_write_ply(const char *path, const rcu_mesh *mesh)
{
    enum { CHUNK = 4096 };
    unsigned char buf[CHUNK * 13];
    FILE *f = fopen(path, "wb");
    uint32_t i, n;
    if (!f) return rcu_fail("%s: %s", path, strerror(errno));
    fprintf(f,
            "ply\nformat binary_little_endian 1.0\ncomment written by rangecast\n"
            "element vertex %u\nproperty float x\nproperty float y\nproperty float z\n"
            "element face %u\nproperty list uchar int vertex_indices\nend_header\n",
            mesh->vertex_count, mesh->triangle_count);
    for (i = 0; i < mesh->vertex_count; i += n) {
        uint32_t j;
        n = mesh->vertex_count - i < CHUNK ? mesh->vertex_count - i : CHUNK;
        for (j = 0; j < 3u * n; j++) rcu_store_f32le(buf + 4u * j, mesh->vertices[3u * (size_t)i + j]);
        if (fwrite(buf, 12, n, f) != n) goto fail;
    }
    for (i = 0; i < mesh->triangle_count; i += n) {
        uint32_t j;
        n = mesh->triangle_count - i < CHUNK ? mesh->triangle_count - i : CHUNK;
        for (j = 0; j < n; j++) {
            const uint32_t *t = mesh->indices + 3u * ((size_t)i + j);
            buf[13u * j] = 3;
            rcu_store_le32(buf + 13u * j + 1, t[0]);
            rcu_store_le32(buf + 13u * j + 5, t[1]);
            rcu_store_le32(buf + 13u * j + 9, t[2]);
        }
        if (fwrite(buf, 13, n, f) != n) goto fail;
    }
    if (fclose(f) != 0) goto removed;
    return 0;
fail:
    fclose(f);
removed: /* nothing half-written stays behind */
    rcu_remove_partial(path);
    return rcu_fail("%s: write error", path);
}
