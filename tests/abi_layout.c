/* Prints the layout of every public struct of rangecast.h: size and alignment
 * of each struct, offset and size of each field, and the padding between them.
 *
 *   abi_layout            prints the layout
 *   abi_layout DIR        compares it with DIR/lp64.txt (8-byte pointers:
 *                         x86_64, aarch64, riscv64) or DIR/ilp32.txt (armhf)
 *
 * The abi_layout test runs the second form on every build, natively or under
 * qemu-user, so x86_64, aarch64 and armhf are each held to the golden file of
 * their pointer size; between the two files only pointer and size_t fields,
 * and the offsets and padding that follow from them, may differ.
 *
 * Exits 1 on a difference, or when a struct's listed fields do not account for
 * its size (a field added to the header but not here). After an intended change
 * (appending a field), regenerate both files with `make abi-golden`. */
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "rangecast/rangecast.h"

#define ALIGNOF(T) offsetof(struct { char c; T t; }, t)

static char text[32768];
static size_t text_len;

/* Everything goes into text[], printed or compared at the end. */
static void out(const char *fmt, ...)
{
    va_list ap;
    int n;
    va_start(ap, fmt);
    n = vsnprintf(text + text_len, sizeof text - text_len, fmt, ap);
    va_end(ap);
    if (n > 0) text_len += (size_t)n;
    if (text_len >= sizeof text) {
        fputs("abi_layout: output buffer too small\n", stderr);
        text_len = sizeof text - 1;
    }
}

static const char *cur_name;
static size_t cur_size, cur_align, cur_end;
static int errors;

static void begin(const char *name, size_t size, size_t align)
{
    cur_name = name;
    cur_size = size;
    cur_align = align;
    cur_end = 0;
    out("%s size %lu align %lu\n", name, (unsigned long)size, (unsigned long)align);
}

static void field(const char *name, size_t offset, size_t size)
{
    if (offset > cur_end) out("  pad %lu\n", (unsigned long)(offset - cur_end));
    if (offset < cur_end) {
        fprintf(stderr, "abi_layout: %s.%s at %lu overlaps the field before it (listed out of order?)\n",
                cur_name, name, (unsigned long)offset);
        errors++;
    }
    out("  %-22s %4lu %4lu\n", name, (unsigned long)offset, (unsigned long)size);
    cur_end = offset + size;
}

static void end(void)
{
    if (cur_size > cur_end) out("  pad %lu\n", (unsigned long)(cur_size - cur_end));
    if (cur_size - cur_end >= cur_align) {
        fprintf(stderr, "abi_layout: %s has %lu bytes after its last listed field: a field missing here?\n",
                cur_name, (unsigned long)(cur_size - cur_end));
        errors++;
    }
}

#define S(T) begin(#T, sizeof(T), ALIGNOF(T))
#define F(T, f) field(#f, offsetof(T, f), sizeof(((T *)0)->f))

/* Compares text[] with the golden file line by line; prints the first difference. */
static int compare(const char *dir)
{
    static char golden[32768];
    char path[4096];
    const char *name = sizeof(void *) == 8 ? "lp64.txt" : "ilp32.txt";
    const char *a = text, *b = golden;
    size_t n;
    unsigned line = 1;
    FILE *f;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "abi_layout: cannot read %s\n", path);
        return 1;
    }
    n = fread(golden, 1, sizeof golden - 1, f);
    fclose(f);
    golden[n] = 0;
    while (*a || *b) {
        size_t la = strcspn(a, "\n"), lb = strcspn(b, "\n");
        if (la != lb || memcmp(a, b, la) != 0) {
            fprintf(stderr, "abi_layout: layout differs from %s at line %u\n  expected: %.*s\n  actual:   %.*s\n"
                    "(an intended change: make abi-golden; the full layout follows)\n",
                    path, line, (int)lb, b, (int)la, a);
            fputs(text, stdout);
            return 1;
        }
        a += la + (a[la] == '\n');
        b += lb + (b[lb] == '\n');
        line++;
    }
    printf("abi_layout: matches %s (%u lines)\n", path, line - 1);
    return 0;
}

int main(int argc, char **argv)
{
    out("# pointer %lu size_t %lu uint64_t align %lu double align %lu\n", (unsigned long)sizeof(void *),
           (unsigned long)sizeof(size_t), (unsigned long)ALIGNOF(uint64_t), (unsigned long)ALIGNOF(double));

    S(rc_pose);
    F(rc_pose, position); F(rc_pose, orientation);
    end();

    S(rc_context_desc);
    F(rc_context_desc, struct_size); F(rc_context_desc, backend); F(rc_context_desc, thread_count);
    F(rc_context_desc, flags); F(rc_context_desc, memory); F(rc_context_desc, memory_size);
    F(rc_context_desc, log); F(rc_context_desc, log_user); F(rc_context_desc, device);
    F(rc_context_desc, backend_budget_mib); F(rc_context_desc, reserved);
    end();

    S(rc_memory_stats);
    F(rc_memory_stats, struct_size); F(rc_memory_stats, reserved0); F(rc_memory_stats, arena_size);
    F(rc_memory_stats, arena_used); F(rc_memory_stats, arena_peak); F(rc_memory_stats, backend_bytes);
    F(rc_memory_stats, device_bytes); F(rc_memory_stats, reserved);
    end();

    S(rc_scene_desc);
    F(rc_scene_desc, struct_size); F(rc_scene_desc, max_geometries); F(rc_scene_desc, max_instances);
    F(rc_scene_desc, flags); F(rc_scene_desc, max_triangles); F(rc_scene_desc, max_vertices);
    F(rc_scene_desc, max_copied_triangles); F(rc_scene_desc, origin); F(rc_scene_desc, build_quality);
    F(rc_scene_desc, reserved);
    end();

    S(rc_mesh_desc);
    F(rc_mesh_desc, struct_size); F(rc_mesh_desc, flags); F(rc_mesh_desc, vertices);
    F(rc_mesh_desc, vertex_count); F(rc_mesh_desc, vertex_stride); F(rc_mesh_desc, reserved0);
    F(rc_mesh_desc, indices); F(rc_mesh_desc, triangle_count); F(rc_mesh_desc, reserved);
    end();

    S(rc_instance_desc);
    F(rc_instance_desc, struct_size); F(rc_instance_desc, reserved0); F(rc_instance_desc, source);
    F(rc_instance_desc, transform); F(rc_instance_desc, scale); F(rc_instance_desc, reserved);
    end();

    S(rc_scene_info);
    F(rc_scene_info, struct_size); F(rc_scene_info, geometry_count); F(rc_scene_info, instance_count);
    F(rc_scene_info, committed); F(rc_scene_info, triangle_count); F(rc_scene_info, bvh_nodes);
    F(rc_scene_info, bytes); F(rc_scene_info, reserved);
    end();

    S(rc_sensor_common);
    F(rc_sensor_common, range_min); F(rc_sensor_common, range_max); F(rc_sensor_common, sensor_to_base);
    end();

    S(rc_angle_axis);
    F(rc_angle_axis, min); F(rc_angle_axis, increment); F(rc_angle_axis, count);
    end();

    S(rc_spherical_desc);
    F(rc_spherical_desc, struct_size); F(rc_spherical_desc, reserved0); F(rc_spherical_desc, common);
    F(rc_spherical_desc, theta); F(rc_spherical_desc, phi); F(rc_spherical_desc, reserved);
    end();

    S(rc_pinhole_desc);
    F(rc_pinhole_desc, struct_size); F(rc_pinhole_desc, frame); F(rc_pinhole_desc, common);
    F(rc_pinhole_desc, width); F(rc_pinhole_desc, height); F(rc_pinhole_desc, fx); F(rc_pinhole_desc, fy);
    F(rc_pinhole_desc, cx); F(rc_pinhole_desc, cy); F(rc_pinhole_desc, reserved);
    end();

    S(rc_cylindrical_desc);
    F(rc_cylindrical_desc, struct_size); F(rc_cylindrical_desc, reserved0); F(rc_cylindrical_desc, common);
    F(rc_cylindrical_desc, theta); F(rc_cylindrical_desc, height); F(rc_cylindrical_desc, fy);
    F(rc_cylindrical_desc, cy); F(rc_cylindrical_desc, reserved);
    end();

    S(rc_rays_desc);
    F(rc_rays_desc, struct_size); F(rc_rays_desc, reserved0); F(rc_rays_desc, common);
    F(rc_rays_desc, directions); F(rc_rays_desc, origins); F(rc_rays_desc, ray_count);
    F(rc_rays_desc, width); F(rc_rays_desc, height); F(rc_rays_desc, reserved);
    end();

    S(rc_sensor_info);
    F(rc_sensor_info, struct_size); F(rc_sensor_info, model); F(rc_sensor_info, rows);
    F(rc_sensor_info, columns); F(rc_sensor_info, rays_per_scan); F(rc_sensor_info, range_min);
    F(rc_sensor_info, range_max); F(rc_sensor_info, reserved);
    end();

    S(rc_noise_desc);
    F(rc_noise_desc, struct_size); F(rc_noise_desc, reserved0); F(rc_noise_desc, mean); F(rc_noise_desc, sigma);
    F(rc_noise_desc, sigma_exponent); F(rc_noise_desc, dropout); F(rc_noise_desc, seed);
    F(rc_noise_desc, reserved);
    end();

    S(rc_ouster_desc);
    F(rc_ouster_desc, struct_size); F(rc_ouster_desc, beams); F(rc_ouster_desc, columns);
    F(rc_ouster_desc, reserved0); F(rc_ouster_desc, altitudes_deg); F(rc_ouster_desc, azimuths_deg);
    F(rc_ouster_desc, beam_to_lidar); F(rc_ouster_desc, lidar_to_sensor); F(rc_ouster_desc, reserved);
    end();

    S(rc_results);
    F(rc_results, struct_size); F(rc_results, attributes); F(rc_results, capacity); F(rc_results, hits);
    F(rc_results, ranges); F(rc_results, points); F(rc_results, normals); F(rc_results, prim_ids);
    F(rc_results, geom_ids); F(rc_results, inst_ids); F(rc_results, flags); F(rc_results, reserved);
    end();

    S(rc_device_results);
    F(rc_device_results, struct_size); F(rc_device_results, attributes); F(rc_device_results, elements);
    F(rc_device_results, buffer); F(rc_device_results, bytes); F(rc_device_results, offsets);
    F(rc_device_results, instance); F(rc_device_results, physical_device); F(rc_device_results, device);
    F(rc_device_results, queue_family); F(rc_device_results, reserved);
    end();

    if (argc > 1) return compare(argv[1]) || errors ? 1 : 0;
    fputs(text, stdout);
    return errors ? 1 : 0;
}
