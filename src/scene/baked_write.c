/* Writing a baked map (baked_format.h): the committed scene's meshes and
 * 4-wide trees, section by section, zero padding between, checksum last. */
#include "scene/baked_format.h"
#include "scene/scene.h"

typedef struct geom_sections {
    uint64_t vertices, indices, refs, leaf_tris, nodes, end;
} geom_sections;

/* Offsets of geometry g's sections when its first one starts at off. */
static void sections_of(const rc__mesh *m, uint64_t off, geom_sections *s)
{
    const uint64_t t = m->triangle_count;
    s->vertices = rc__bk_align(off);
    s->indices = rc__bk_align(s->vertices + (uint64_t)m->vertex_count * RC__BAKED_VERTEX_FLOATS * sizeof(float));
    s->refs = rc__bk_align(s->indices + t * 3u * sizeof(uint32_t));
    s->leaf_tris = rc__bk_align(s->refs + t * sizeof(uint32_t));
    s->nodes = rc__bk_align(s->leaf_tris + t * 3u * sizeof(uint32_t));
    s->end = s->nodes + (uint64_t)m->wide_count * sizeof(rc__wnode);
}

uint64_t rc__scene_baked_bytes(const rc_scene *scene)
{
    uint64_t off = rc__bk_header_bytes(scene->geom_count);
    uint32_t g;
    for (g = 0; g < scene->geom_count; ++g) {
        geom_sections s;
        sections_of(&scene->geoms[g].mesh, off, &s);
        off = s.end;
    }
    return rc__bk_align(off);
}

uint32_t rc__baked_checksum(const unsigned char *blob, size_t bytes)
{
    static const unsigned char zero[4] = {0, 0, 0, 0};
    uint32_t c = rc__crc32c(0, blob, RC__BK_CHECKSUM);
    c = rc__crc32c(c, zero, sizeof zero);
    return rc__crc32c(c, blob + RC__BK_CHECKSUM + 4u, bytes - (RC__BK_CHECKSUM + 4u));
}

void rc__scene_bake(const rc_scene *scene, unsigned char *blob)
{
    const uint64_t total = rc__scene_baked_bytes(scene);
    const uint32_t byte_order = RC__BAKED_BYTE_ORDER;
    uint64_t off = rc__bk_header_bytes(scene->geom_count);
    uint32_t g;
    memset(blob, 0, (size_t)total);
    memcpy(blob, RC__BAKED_MAGIC, 8);
    rc__bk_put32(blob, RC__BK_VERSION, RC_BAKED_MAP_VERSION);
    rc__bk_put32(blob, RC__BK_BYTE_ORDER, byte_order);
    rc__bk_put32(blob, RC__BK_HEADER_BYTES, (uint32_t)off);
    rc__bk_put64(blob, RC__BK_TOTAL, total);
    rc__bk_put32(blob, RC__BK_GEOMETRIES, scene->geom_count);
    rc__bk_put32(blob, RC__BK_NODE_BYTES, (uint32_t)sizeof(rc__wnode));
    rc__bk_put32(blob, RC__BK_LEAF_SIZE, RC__BVH_MESH_LEAF_SIZE);
    rc__bk_put32(blob, RC__BK_VERTEX_FLOATS, RC__BAKED_VERTEX_FLOATS);
    memcpy(blob + RC__BK_ORIGIN, scene->desc.origin, sizeof scene->desc.origin);
    rc__bk_put32(blob, RC__BK_QUALITY, scene->desc.build_quality);
    for (g = 0; g < scene->geom_count; ++g) {
        const rc__mesh *m = &scene->geoms[g].mesh;
        unsigned char *rec = blob + RC__BAKED_HEADER + (size_t)g * RC__BAKED_RECORD;
        geom_sections s;
        uint32_t i;
        sections_of(m, off, &s);
        rc__bk_put32(rec, RC__BR_VERTICES, m->vertex_count);
        rc__bk_put32(rec, RC__BR_TRIANGLES, m->triangle_count);
        rc__bk_put32(rec, RC__BR_NODES, m->wide_count);
        rc__bk_put64(rec, RC__BR_OFF_VERTICES, s.vertices);
        rc__bk_put64(rec, RC__BR_OFF_INDICES, s.indices);
        rc__bk_put64(rec, RC__BR_OFF_REFS, s.refs);
        rc__bk_put64(rec, RC__BR_OFF_LEAF_TRIS, s.leaf_tris);
        rc__bk_put64(rec, RC__BR_OFF_NODES, s.nodes);
        for (i = 0; i < m->vertex_count; ++i) /* x y z, then the pad float stays 0 */
            memcpy(blob + s.vertices + (size_t)i * 16u, m->vertices + (size_t)i * m->stride, 3 * sizeof(float));
        memcpy(blob + s.indices, m->indices, (size_t)m->triangle_count * 3u * sizeof(uint32_t));
        memcpy(blob + s.refs, m->bvh.refs, (size_t)m->triangle_count * sizeof(uint32_t));
        /* the triples as the format has them, whole (the mesh's own copy
         * has its zero-area triangles folded: rc__mesh_fold_flats); what
         * rc__mesh_fill_leaf_tris writes, byte-wise here because a bake's
         * buffer need not be aligned */
        for (i = 0; i < m->triangle_count; ++i)
            memcpy(blob + s.leaf_tris + (size_t)i * 12u, m->indices + (size_t)3 * m->bvh.refs[i], 12);
        memcpy(blob + s.nodes, m->wide, (size_t)m->wide_count * sizeof(rc__wnode));
        off = s.end;
    }
    rc__bk_put32(blob, RC__BK_CHECKSUM, rc__baked_checksum(blob, (size_t)total));
}
