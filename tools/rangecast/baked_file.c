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

int rcp_baked_load_mesh(const char *path, rcu_mesh *out)
{
    rcp_baked b;
    rc_mesh_desc md = rc_mesh_desc_default();
    uint32_t geoms = 0;
    uint64_t i;
    rc_status st;
    memset(out, 0, sizeof *out);
    if (map_count == MAX_MAPS) return rcu_fail("%s: more than %d baked maps open", path, MAX_MAPS);
    if (map_file(path, &b) != 0) return -1;
    st = rc_baked_get_mesh(b.blob, b.bytes, 0, &md, &geoms);
    if (st == RC_OK && geoms != 1) {
        /* the commands read a map as one mesh: their float64 reference finds
         * a hit's triangle by its prim id alone */
        rcu_fail("%s holds %u geometries; this program reads baked maps of one mesh, as 'rangecast bake' "
                 "writes them (load others with rc_scene_load_baked)",
                 path, (unsigned)geoms);
    } else if (st != RC_OK) {
        rcu_fail("%s: %s; bake it again with 'rangecast bake'", path, header_problem(&b, st));
    } else if (rcu_mesh_reserve(out, md.vertex_count, md.triangle_count) != 0) {
        rcu_fail("%s: out of memory copying its triangles", path);
    } else {
        for (i = 0; i < md.vertex_count; ++i) /* 16-byte vertices to packed xyz */
            memcpy(out->vertices + 3u * (size_t)i, md.vertices + 4u * (size_t)i, 3 * sizeof(float));
        memcpy(out->indices, md.indices, (size_t)md.triangle_count * 3u * sizeof(uint32_t));
        out->vertex_count = (uint32_t)md.vertex_count;
        out->triangle_count = (uint32_t)md.triangle_count;
        maps[map_count].vertices = out->vertices;
        maps[map_count].baked = b;
        map_count++;
        return 0;
    }
    rcu_mesh_free(out);
    munmap((void *)(uintptr_t)b.blob, b.bytes);
    return -1;
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
