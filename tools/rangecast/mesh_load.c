#include "mesh_load.h"

#include <stdlib.h>
#include <string.h>

#include "baked_file.h"
#include "ply.h"
#include "util.h"

#if defined(RANGECAST_WITH_ASSIMP)
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

/* 4x4 row-major (Assimp's a1..d4 layout). */
typedef struct mat4 {
    double m[4][4];
} mat4;

static mat4 mat4_from_ai(const struct aiMatrix4x4 *a)
{
    mat4 r;
    r.m[0][0] = a->a1; r.m[0][1] = a->a2; r.m[0][2] = a->a3; r.m[0][3] = a->a4;
    r.m[1][0] = a->b1; r.m[1][1] = a->b2; r.m[1][2] = a->b3; r.m[1][3] = a->b4;
    r.m[2][0] = a->c1; r.m[2][1] = a->c2; r.m[2][2] = a->c3; r.m[2][3] = a->c4;
    r.m[3][0] = a->d1; r.m[3][1] = a->d2; r.m[3][2] = a->d3; r.m[3][3] = a->d4;
    return r;
}

static mat4 mat4_mul(const mat4 *a, const mat4 *b)
{
    mat4 r;
    int i, j, k;
    for (i = 0; i < 4; i++)
        for (j = 0; j < 4; j++) {
            double s = 0.0;
            for (k = 0; k < 4; k++) s += a->m[i][k] * b->m[k][j];
            r.m[i][j] = s;
        }
    return r;
}

/* Counts (pass 1, out->vertices NULL) or copies (pass 2) the node's meshes. */
static int visit(const struct aiScene *sc, const struct aiNode *node, const mat4 *parent, rcu_mesh *out,
                 uint64_t *nv, uint64_t *nt)
{
    mat4 local = mat4_from_ai(&node->mTransformation), world = mat4_mul(parent, &local);
    unsigned i, j;
    for (i = 0; i < node->mNumMeshes; i++) {
        const struct aiMesh *m = sc->mMeshes[node->mMeshes[i]];
        uint32_t base = (uint32_t)*nv;
        if (!(m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
        if (out->vertices) {
            for (j = 0; j < m->mNumVertices; j++) {
                const struct aiVector3D *p = &m->mVertices[j];
                float *v = out->vertices + 3u * (size_t)(*nv + j);
                int r;
                for (r = 0; r < 3; r++)
                    v[r] = (float)(world.m[r][0] * p->x + world.m[r][1] * p->y + world.m[r][2] * p->z +
                                   world.m[r][3]);
            }
        }
        *nv += m->mNumVertices;
        for (j = 0; j < m->mNumFaces; j++) {
            const struct aiFace *f = &m->mFaces[j];
            if (f->mNumIndices != 3) continue;
            if (out->indices) {
                uint32_t *t = out->indices + 3u * (size_t)*nt;
                t[0] = base + f->mIndices[0];
                t[1] = base + f->mIndices[1];
                t[2] = base + f->mIndices[2];
            }
            ++*nt;
        }
        if (*nv > UINT32_MAX || *nt > UINT32_MAX) return rcu_fail("more than 2^32 vertices or triangles");
    }
    for (i = 0; i < node->mNumChildren; i++)
        if (visit(sc, node->mChildren[i], &world, out, nv, nt) != 0) return -1;
    return 0;
}

static int load_assimp(const char *path, const char *ext, rcu_mesh *out)
{
    /* JoinIdenticalVertices costs seconds on million-triangle files; it pays
     * only for STL, which stores each triangle's corners separately (it cuts
     * the vertex array 6x). Measured on a 1M-triangle sphere: OBJ 0.79 s
     * without it (Assimp de-indexes OBJ: 3M vertices) vs 2.17 s with it
     * (500k); STL 1.7 s with it; our own PLY reader 0.06 s. Vertices are
     * referenced in place, so the extra copies cost tool memory, not arena. */
    unsigned flags = aiProcess_Triangulate | aiProcess_SortByPType;
    const struct aiScene *sc;
    mat4 id;
    uint64_t nv = 0, nt = 0;
    int i, j;
    if (strcmp(ext, "stl") == 0) flags |= aiProcess_JoinIdenticalVertices;
    sc = aiImportFile(path, flags);
    if (!sc || !sc->mRootNode) return rcu_fail("%s: %s", path, aiGetErrorString());
    for (i = 0; i < 4; i++)
        for (j = 0; j < 4; j++) id.m[i][j] = i == j ? 1.0 : 0.0;
    memset(out, 0, sizeof *out);
    if (visit(sc, sc->mRootNode, &id, out, &nv, &nt) != 0) goto fail;
    if (nt == 0) {
        rcu_fail("%s: no triangles in the file", path);
        goto fail;
    }
    if (rcu_mesh_reserve(out, nv, nt) != 0) goto fail;
    nv = nt = 0;
    if (visit(sc, sc->mRootNode, &id, out, &nv, &nt) != 0) goto fail;
    out->vertex_count = (uint32_t)nv;
    out->triangle_count = (uint32_t)nt;
    aiReleaseImport(sc);
    return 0;
fail:
    rcu_mesh_free(out);
    aiReleaseImport(sc);
    return -1;
}
#endif

const char *rcp_mesh_formats(void)
{
#if defined(RANGECAST_WITH_ASSIMP)
    return "ply (built-in reader), rcmap (baked maps); obj, stl, off, dae, gltf, glb, fbx, 3ds and the rest through Assimp";
#else
    return "ply and rcmap (baked maps) only (this program was built without Assimp)";
#endif
}

int rcp_mesh_load(const char *path, rcu_mesh *out)
{
    char ext[16];
    rcu_path_extension(path, ext, sizeof ext);
    memset(out, 0, sizeof *out);
    if (strcmp(ext, "ply") == 0) return rcu_mesh_read_ply(path, out);
    if (strcmp(ext, "rcmap") == 0) return rcp_baked_load_mesh(path, out);
#if defined(RANGECAST_WITH_ASSIMP)
    return load_assimp(path, ext, out);
#else
    return rcu_fail("%s: cannot read '.%s' files: this rangecast was built without Assimp, so maps "
                    "must be .ply or .rcmap", path, ext);
#endif
}
