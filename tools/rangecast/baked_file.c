#include "baked_file.h"

#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "rangecast/rangecast.h"
#include "util.h"

/* Maps a program opens: a few maps per run at most. */
#define MAX_MAPS 8

static struct {
    const float *vertices; /* the copy's vertex array: identifies the mesh */
    rcp_baked baked;
    uint64_t *first_triangle; /* geometry g's triangles start here in the copy (geoms + 1 entries) */
    uint32_t geoms;
} maps[MAX_MAPS];
static unsigned map_count;

static int map_file(const char *path, rcp_baked *out)
{
    struct stat st;
    void *p;
    int fd = open(path, O_RDONLY);
    if (fd < 0) return rcu_fail("%s: %s", path, strerror(errno));
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || st.st_size <= 0) {
        close(fd);
        return rcu_fail("%s: not a regular, non-empty file", path);
    }
    if ((uint64_t)st.st_size > (uint64_t)SIZE_MAX) {
        close(fd);
        return rcu_fail("%s: %llu bytes is more than this machine can map", path, (unsigned long long)st.st_size);
    }
    p = mmap(NULL, (size_t)st.st_size, PROT_READ, MAP_PRIVATE, fd, 0);
    close(fd);
    if (p == MAP_FAILED) return rcu_fail("%s: mmap: %s", path, strerror(errno));
    out->blob = p;
    out->bytes = (size_t)st.st_size;
    return 0;
}

/* The library's words for what is wrong with b's header: rc_baked_get_mesh
 * has no context to leave a message in, so ask one that has. */
static const char *header_problem(const rcp_baked *b, rc_status st)
{
    static char text[512];
    rc_context_desc d = rc_context_desc_default();
    rc_context *ctx = NULL;
    size_t bytes = 0;
    snprintf(text, sizeof text, "not a baked map this rangecast reads (%s)", rc_status_string(st));
    d.backend = RC_BACKEND_BVH;
    d.thread_count = 1;
    d.memory_size = (size_t)1 << 16;
    if (rc_context_create(&d, &ctx) == RC_OK) {
        if (rc_scene_baked_memory_requirements(ctx, b->blob, b->bytes, &bytes) != RC_OK)
            snprintf(text, sizeof text, "%s", rc_context_last_error(ctx));
        rc_context_destroy(ctx);
    }
    return text;
}

/* Copies a geometry of a baked map into out after what out holds (vertex
 * indices offset by it; out has the room). */
static void append_geometry(const rc_mesh_desc *md, rcu_mesh *out)
{
    const uint64_t v0 = out->vertex_count, t0 = out->triangle_count;
    uint64_t i;
    for (i = 0; i < md->vertex_count; ++i) /* 16-byte vertices to packed xyz */
        memcpy(out->vertices + 3u * (size_t)(v0 + i), md->vertices + 4u * (size_t)i, 3 * sizeof(float));
    for (i = 0; i < 3u * md->triangle_count; ++i) out->indices[3u * t0 + i] = md->indices[i] + (uint32_t)v0;
    out->vertex_count = (uint32_t)(v0 + md->vertex_count);
    out->triangle_count = (uint32_t)(t0 + md->triangle_count);
}

int rcp_baked_load_mesh(const char *path, rcu_mesh *out)
{
    rcp_baked b;
    rc_mesh_desc *md = NULL;
    uint32_t geoms = 0, g;
    uint64_t *first = NULL, vertices = 0, triangles = 0;
    rc_status st;
    memset(out, 0, sizeof *out);
    if (map_count == MAX_MAPS) return rcu_fail("%s: more than %d baked maps open", path, MAX_MAPS);
    if (map_file(path, &b) != 0) return -1;
    st = rc_baked_get_mesh(b.blob, b.bytes, 0, NULL, &geoms);
    if (st == RC_OK) {
        md = (rc_mesh_desc *)malloc(sizeof *md * ((size_t)geoms + 1u));
        first = (uint64_t *)malloc(sizeof *first * ((size_t)geoms + 1u));
    }
    for (g = 0; st == RC_OK && md && g < geoms; ++g) { /* the sizes first: one copy holds them all */
        md[g] = rc_mesh_desc_default();
        if ((st = rc_baked_get_mesh(b.blob, b.bytes, g, &md[g], NULL)) == RC_OK) {
            vertices += md[g].vertex_count;
            triangles += md[g].triangle_count;
        }
    }
    if (st != RC_OK) {
        rcu_fail("%s: %s; bake it again with 'rangecast bake'", path, header_problem(&b, st));
    } else if (!md || !first) {
        rcu_fail("%s: out of memory for %u geometry records", path, (unsigned)geoms);
    } else if (rcu_mesh_reserve(out, vertices, triangles) == 0) {
        /* the geometries one after another in one copy: the commands' float64
         * reference finds a hit's triangle at first[geom id] + prim id */
        for (g = 0; g < geoms; ++g) {
            first[g] = out->triangle_count;
            append_geometry(&md[g], out);
        }
        first[geoms] = out->triangle_count;
        free(md);
        maps[map_count].vertices = out->vertices;
        maps[map_count].baked = b;
        maps[map_count].first_triangle = first;
        maps[map_count].geoms = geoms;
        map_count++;
        return 0;
    } else {
        rcu_fail("%s: %s", path, rcu_last_error());
    }
    free(md);
    free(first);
    rcu_mesh_free(out);
    munmap((void *)(uintptr_t)b.blob, b.bytes);
    return -1;
}

uint64_t rcp_mesh_triangle(const rcu_mesh *mesh, uint32_t geom, uint32_t prim)
{
    unsigned k;
    for (k = 0; mesh && mesh->vertices && k < map_count; ++k)
        if (maps[k].vertices == mesh->vertices) {
            if (geom >= maps[k].geoms || prim >= maps[k].first_triangle[geom + 1u] - maps[k].first_triangle[geom])
                return UINT64_MAX;
            return maps[k].first_triangle[geom] + prim;
        }
    return geom == 0 && mesh && prim < mesh->triangle_count ? prim : UINT64_MAX;
}

const rcp_baked *rcp_baked_of(const rcu_mesh *mesh)
{
    unsigned k;
    for (k = 0; mesh && mesh->vertices && k < map_count; ++k)
        if (maps[k].vertices == mesh->vertices) return &maps[k].baked;
    return NULL;
}

int rcp_baked_write(const char *path, const void *blob, size_t bytes)
{
    char tmp[4096];
    FILE *f;
    int ok;
    if ((size_t)snprintf(tmp, sizeof tmp, "%s.part%ld", path, (long)getpid()) >= sizeof tmp)
        return rcu_fail("%s: path too long", path);
    f = fopen(tmp, "wb");
    if (f == NULL) return rcu_fail("%s: %s", tmp, strerror(errno));
    ok = fwrite(blob, 1, bytes, f) == bytes;
    ok = (fclose(f) == 0) && ok;
    if (!ok || rename(tmp, path) != 0) {
        const int e = errno;
        remove(tmp);
        return rcu_fail("%s: %s", ok ? path : tmp, strerror(e ? e : EIO));
    }
    return 0;
}
