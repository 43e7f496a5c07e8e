/* Scene storage: one arena block per scene holding the object, its geometry
 * and instance tables, and the space for copied meshes. */
#include "scene/scene.h"

#include <string.h>

int rc__scene_valid(const rc_scene *scene)
{
    return scene != NULL && scene->magic == RC__MAGIC_SCENE && rc__context_valid(scene->ctx);
}

/* Layout of the scene block, in order, each part 16-aligned. */
typedef struct scene_layout {
    size_t geoms, insts, versions, vertices, indices, total;
} scene_layout;

static size_t align16(size_t n) { return (n + 15u) & ~(size_t)15u; }

static void layout_of(const rc_scene_desc *d, scene_layout *l)
{
    size_t off = align16(sizeof(rc_scene));
    uint32_t geoms = d->max_geometries ? d->max_geometries : 1u;
    l->geoms = off;
    off += align16(sizeof(rc__geometry) * geoms);
    l->insts = off;
    off += align16(sizeof(rc__instance) * d->max_instances);
    l->versions = off;
    off += align16(sizeof(uint64_t) * d->max_instances);
    l->vertices = off;
    off += align16((size_t)d->max_vertices * 3u * sizeof(float));
    l->indices = off;
    off += align16((size_t)d->max_copied_triangles * 3u * sizeof(uint32_t));
    l->total = off;
}

size_t rc__scene_object_bytes(const rc_scene_desc *desc)
{
    scene_layout l;
    layout_of(desc, &l);
    return rc__arena_cost(l.total);
}

rc_scene *rc__scene_place(void *block, const rc_scene_desc *desc);
rc_scene *rc__scene_place(void *block, const rc_scene_desc *desc)
{
    scene_layout l;
    unsigned char *b = (unsigned char *)block;
    rc_scene *s = (rc_scene *)block;
    layout_of(desc, &l);
    memset(s, 0, sizeof *s);
    s->desc = *desc;
    if (s->desc.max_geometries == 0) s->desc.max_geometries = 1;
    s->geoms = (rc__geometry *)(void *)(b + l.geoms);
    memset(s->geoms, 0, sizeof(rc__geometry) * s->desc.max_geometries);
    s->insts = desc->max_instances ? (rc__instance *)(void *)(b + l.insts) : NULL;
    s->source_versions = desc->max_instances ? (uint64_t *)(void *)(b + l.versions) : NULL;
    s->copy_vertices = desc->max_vertices ? (float *)(void *)(b + l.vertices) : NULL;
    s->copy_indices = desc->max_copied_triangles ? (uint32_t *)(void *)(b + l.indices) : NULL;
    return s;
}

int rc__scene_up_to_date(const rc_scene *scene)
{
    uint32_t i;
    if (!scene->committed) return 0;
    for (i = 0; i < scene->inst_count; ++i) {
        const rc_scene *src = scene->insts[i].source;
        if (!src->committed || src->version != scene->source_versions[i]) return 0;
    }
    return 1;
}
