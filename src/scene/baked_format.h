/* The baked-map blob (docs/baked-map.md): a header, one record per geometry,
 * then each geometry's arrays, every section on a 64-byte boundary of the
 * blob. Every field is a little-endian uint32, uint64, float or double at its
 * natural alignment, so the blob is the same on every target this library
 * builds for. Fields are read and written with memcpy (a blob in flash may
 * sit at any 16-byte boundary, and strict aliasing forbids casting it).
 *
 * header (128 bytes)
 *   0   magic        8 bytes "\x89RCMAP\r\n" (the line ends catch text-mode copies)
 *   8   version      u32 RC_BAKED_MAP_VERSION
 *   12  byte_order   u32 0x01020304 as the writer stored it
 *   16  header_bytes u32 128 + 64 * geometry_count, rounded up to 64
 *   20  checksum     u32 CRC-32C of the whole blob with these 4 bytes as zero
 *   24  total_bytes  u64
 *   32  geometry_count u32
 *   36  node_bytes   u32 sizeof(rc__wnode) = 128
 *   40  leaf_size    u32 triangles a leaf may hold (4)
 *   44  vertex_floats u32 floats per vertex (4: x, y, z, 0; Embree shares 16-byte vertices in place)
 *   48  origin       3 x f64 (rc_scene_desc.origin)
 *   72  build_quality u32 (rc_scene_desc.build_quality)
 *   76  reserved     52 bytes of zero
 * geometry record (64 bytes), geometry g at 128 + 64 g
 *   0   vertex_count u32, 4 triangle_count u32, 8 node_count u32, 12 reserved u32
 *   16  vertices  u64 offset (vertex_count * 16 bytes)
 *   24  indices   u64 offset (triangle_count * 12: the mesh's triangles in their order)
 *   32  refs      u64 offset (triangle_count * 4: triangle index of each leaf slot)
 *   40  leaf_tris u64 offset (triangle_count * 12: the vertex indices of each leaf slot)
 *   48  nodes     u64 offset (node_count * 128: the 4-wide tree, bvh/wide.h)
 *   56  reserved  u64 */
#ifndef RC_SCENE_BAKED_FORMAT_H
#define RC_SCENE_BAKED_FORMAT_H

#include "core/crc32c.h"
#include "rangecast/rangecast.h"

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#define RC__BAKED_MAGIC "\x89RCMAP\r\n"
#define RC__BAKED_BYTE_ORDER 0x01020304u
#define RC__BAKED_HEADER 128u
#define RC__BAKED_RECORD 64u
#define RC__BAKED_ALIGN 64u
#define RC__BAKED_VERTEX_FLOATS 4u

/* header field offsets */
#define RC__BK_VERSION 8u
#define RC__BK_BYTE_ORDER 12u
#define RC__BK_HEADER_BYTES 16u
#define RC__BK_CHECKSUM 20u
#define RC__BK_TOTAL 24u
#define RC__BK_GEOMETRIES 32u
#define RC__BK_NODE_BYTES 36u
#define RC__BK_LEAF_SIZE 40u
#define RC__BK_VERTEX_FLOATS 44u
#define RC__BK_ORIGIN 48u
#define RC__BK_QUALITY 72u

/* record field offsets */
#define RC__BR_VERTICES 0u
#define RC__BR_TRIANGLES 4u
#define RC__BR_NODES 8u
#define RC__BR_OFF_VERTICES 16u
#define RC__BR_OFF_INDICES 24u
#define RC__BR_OFF_REFS 32u
#define RC__BR_OFF_LEAF_TRIS 40u
#define RC__BR_OFF_NODES 48u

static inline uint32_t rc__bk_u32(const unsigned char *p, size_t off)
{
    uint32_t v;
    memcpy(&v, p + off, sizeof v);
    return v;
}

static inline uint64_t rc__bk_u64(const unsigned char *p, size_t off)
{
    uint64_t v;
    memcpy(&v, p + off, sizeof v);
    return v;
}

static inline void rc__bk_put32(unsigned char *p, size_t off, uint32_t v) { memcpy(p + off, &v, sizeof v); }
static inline void rc__bk_put64(unsigned char *p, size_t off, uint64_t v) { memcpy(p + off, &v, sizeof v); }

static inline uint64_t rc__bk_align(uint64_t n) { return (n + (RC__BAKED_ALIGN - 1u)) & ~(uint64_t)(RC__BAKED_ALIGN - 1u); }

/* header_bytes for a geometry count */
static inline uint64_t rc__bk_header_bytes(uint32_t geometries)
{
    return rc__bk_align((uint64_t)RC__BAKED_HEADER + (uint64_t)RC__BAKED_RECORD * geometries);
}

/* A geometry record, read. */
typedef struct rc__baked_geom {
    uint32_t vertices, triangles, nodes;
    uint64_t off_vertices, off_indices, off_refs, off_leaf_tris, off_nodes;
} rc__baked_geom;

/* Reads record g of a blob whose header passed rc__baked_scene_desc and
 * checks its counts, reserved fields and that every section lies inside the
 * blob on its boundary (not the sections' contents): RC_ERR_CORRUPT_DATA with
 * the message to ctx (may be NULL) otherwise. */
rc_status rc__baked_read_geometry(rc_context *ctx, const unsigned char *blob, uint64_t total, uint32_t g,
                                  rc__baked_geom *r);

/* The blob's checksum: CRC-32C of all of it with the checksum field as zero. */
uint32_t rc__baked_checksum(const unsigned char *blob, size_t bytes);

#endif
