/* rangecast: reads one element of each shared struct (kernels/layout.glsl)
 * through its GLSL declaration and writes every member back as raw words, in
 * declaration order. tests/test_vulkan_layout.c fills the elements from C and
 * compares: the std430 side of the layout contract. */
#version 450
#extension GL_GOOGLE_include_directive : require

#include "layout.glsl"

layout(local_size_x = 1) in;

layout(std430, binding = 0) readonly buffer Nodes { Node n[]; } nodes;
layout(std430, binding = 1) readonly buffer Geoms { Geom g[]; } geoms;
layout(std430, binding = 2) readonly buffer Insts { Inst i[]; } insts;
layout(std430, binding = 3) writeonly buffer Out { uint o[]; } outb;

void main()
{
    /* element 1 of each array, so the array stride is checked too */
    Node n = nodes.n[1];
    Geom g = geoms.g[1];
    Inst in_ = insts.i[1];
    uint k = 0u;
    outb.o[k++] = floatBitsToUint(n.bmin.x);
    outb.o[k++] = floatBitsToUint(n.bmin.y);
    outb.o[k++] = floatBitsToUint(n.bmin.z);
    outb.o[k++] = n.index;
    outb.o[k++] = floatBitsToUint(n.bmax.x);
    outb.o[k++] = floatBitsToUint(n.bmax.y);
    outb.o[k++] = floatBitsToUint(n.bmax.z);
    outb.o[k++] = n.count;
    outb.o[k++] = g.node_base;
    outb.o[k++] = g.ref_base;
    outb.o[k++] = g.tri_base;
    outb.o[k++] = g.geom_id;
    for (uint r = 0u; r < 3u; ++r) {
        outb.o[k++] = floatBitsToUint(in_.to_local[r].x);
        outb.o[k++] = floatBitsToUint(in_.to_local[r].y);
        outb.o[k++] = floatBitsToUint(in_.to_local[r].z);
        outb.o[k++] = floatBitsToUint(in_.to_local[r].w);
    }
    for (uint r = 0u; r < 3u; ++r) {
        outb.o[k++] = floatBitsToUint(in_.n2w[r].x);
        outb.o[k++] = floatBitsToUint(in_.n2w[r].y);
        outb.o[k++] = floatBitsToUint(in_.n2w[r].z);
        outb.o[k++] = floatBitsToUint(in_.n2w[r].w);
    }
    outb.o[k++] = in_.first_geom;
    outb.o[k++] = in_.geom_count;
    outb.o[k++] = in_.pad0;
    outb.o[k++] = in_.pad1;
    for (uint w = 0u; w < 24u; ++w) outb.o[k++] = in_.to_world_d[w];
}
