/* rangecast demo: the front door. Builds the demo warehouse, drives a VLP-16
 * and a RealSense D435 through it, and writes files a newcomer can open:
 * the map, the LiDAR point cloud, its range image and the camera's depth image. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>

#include "cloud.h"
#include "ply.h"
#include "range_image.h"
#include "reference.h"
#include "tool.h"
#include "util.h"

static void usage(FILE *f)
{
    fprintf(f,
        "Usage: rangecast demo [--out DIR] [--backend B] [--threads N]\n"
        "\n"
        "Builds a small warehouse (20 x 12 x 4 m, racks, pillars, a ramp), simulates a\n"
        "Velodyne VLP-16 at two poses and a RealSense D435 in it, and writes:\n"
        "  DIR/demo_map.ply      the map (open it with the clouds in MeshLab/CloudCompare)\n"
        "  DIR/vlp16_scan.ply    the LiDAR returns in the map frame (range, intensity, ring)\n"
        "  DIR/vlp16_scan.pcd    the same for PCL / ROS tools\n"
        "  DIR/vlp16_range.png   range image of the first scan (16 rows, 8 px each)\n"
        "  DIR/d435_depth.png    the camera's depth image (848 x 480)\n"
        "  DIR/d435_cloud.ply    the camera's points in the map frame\n"
        "\n"
        "Options:\n"
        "  --out DIR      output directory (default ./out; created if missing)\n"
        "  --backend B    auto (default), bvh, embree, vulkan\n"
        "  --threads N    worker threads, 0 = all CPUs (default)\n"
        "  -h, --help     this text\n");
}

/* mkdir -p */
static int make_dirs(const char *path)
{
    char buf[4096];
    size_t i, n = strlen(path);
    if (n == 0 || n >= sizeof buf) return rcu_fail("bad directory name '%s'", path);
    memcpy(buf, path, n + 1);
    for (i = 1; i <= n; i++) {
        if (buf[i] == '/' || buf[i] == 0) {
            char c = buf[i];
            buf[i] = 0;
            if (mkdir(buf, 0777) != 0 && errno != EEXIST)
                return rcu_fail("cannot create directory %s: %s", buf, strerror(errno));
            buf[i] = c;
        }
    }
    return 0;
}

static rc_pose pose_yaw_pitch(float x, float y, float z, double yaw, double pitch)
{
    rc_pose p;
    double cz = cos(0.5 * yaw), sz = sin(0.5 * yaw), cy = cos(0.5 * pitch), sy = sin(0.5 * pitch);
    p.position[0] = x;
    p.position[1] = y;
    p.position[2] = z;
    p.orientation[0] = (float)(-sz * sy);
    p.orientation[1] = (float)(cz * sy);
    p.orientation[2] = (float)(sz * cy);
    p.orientation[3] = (float)(cz * cy);
    return p;
}

/* Median seconds of one rc_simulate call over ~0.2 s of repeats. */
static double time_simulate(rc_context *ctx, const rc_scene *scene, const rc_sensor *sensor,
                            const rc_pose *poses, uint32_t n, const rc_results *res)
{
    double t[64], start = rcu_now();
    int k = 0;
    while (k < 64 && (k < 3 || rcu_now() - start < 0.2)) {
        double t0 = rcu_now();
        if (rc_simulate(ctx, scene, sensor, poses, n, res) != RC_OK) return NAN;
        t[k++] = rcu_now() - t0;
    }
    return rcp_median(t, (size_t)k);
}

static void join(char *out, size_t size, const char *dir, const char *name)
{
    snprintf(out, size, "%s/%s", dir, name);
}

int rcp_cmd_demo(int argc, char **argv)
{
    const char *cmd = "demo", *dir = "out";
    uint32_t backend = RC_BACKEND_AUTO, threads = 0;
    static const uint32_t presets[2] = {RC_PRESET_VELODYNE_VLP16, RC_PRESET_REALSENSE_D435};
    rc_pose lidar_poses[2], cam_pose;
    rcu_mesh map;
    rcp_world w;
    rc_sensor_info li = rc_sensor_info_default(), ci = rc_sensor_info_default();
    rcu_preset_rays lref, cref;
    rcu_cloud lcloud, ccloud;
    float *l_points = NULL, *l_ranges = NULL, *l_normals = NULL;
    float *c_points = NULL, *c_ranges = NULL, *c_depth = NULL;
    uint8_t *l_hits = NULL, *c_hits = NULL;
    double l_time, c_time;
    float b[6];
    char path[4096], img_path[4096], n1[32], n2[32], n3[32];
    int i, r, rc = RCP_EXIT_FAIL;
    rc_status st;

    for (i = 1; i < argc; i++) {
        const char *v = NULL;
        if (rcp_is_help(argv[i])) {
            usage(stdout);
            return RCP_EXIT_OK;
        }
        if ((r = rcp_opt(argc, argv, &i, "--out", &v)) != 0) {
            if (r < 0) return RCP_EXIT_USAGE;
            dir = v;
        } else if ((r = rcp_opt(argc, argv, &i, "--backend", &v)) != 0) {
            if (r < 0 || rcp_parse_backend(cmd, v, &backend) != 0) return RCP_EXIT_USAGE;
        } else if ((r = rcp_opt_threads(cmd, argc, argv, &i, &threads)) != 0) {
            if (r < 0) return RCP_EXIT_USAGE;
        } else {
            return rcp_usage_error(cmd, "unknown argument '%s'", argv[i]);
        }
    }

    memset(&w, 0, sizeof w);
    memset(&lref, 0, sizeof lref);
    memset(&cref, 0, sizeof cref);
    rcu_cloud_init(&lcloud, RCU_CLOUD_RANGE | RCU_CLOUD_INTENSITY | RCU_CLOUD_RING);
    rcu_cloud_init(&ccloud, RCU_CLOUD_RANGE);
    if (make_dirs(dir) != 0) return rcp_fail(cmd, "%s", rcu_last_error());
    if (rcu_mesh_demo_map(&map) != 0) return rcp_fail(cmd, "%s", rcu_last_error());
    join(path, sizeof path, dir, "demo_map.ply");
    if (rcu_mesh_write_ply(path, &map) != 0) {
        rcp_fail(cmd, "%s", rcu_last_error());
        goto done;
    }
    if (rcp_world_create(cmd, backend, threads, &map, presets, 2, &w) != RCP_EXIT_OK) goto done;
    rc_sensor_get_info(w.sensors[0], &li);
    rc_sensor_get_info(w.sensors[1], &ci);
    if (rcu_preset_rays_f64(presets[0], &lref) != 0 || rcu_preset_rays_f64(presets[1], &cref) != 0) {
        rcp_fail(cmd, "%s", rcu_last_error());
        goto done;
    }
    rcu_mesh_bounds(&map, b);
    printf("rangecast demo  (library %s, backend %s, %u thread%s)\n\n", rc_version_string(),
           rc_backend_name(w.backend), w.threads, w.threads == 1 ? "" : "s");
    printf("  map     warehouse %.0f x %.0f x %.0f m, %s triangles, built in %.1f ms, arena %s\n",
           (double)(b[3] - b[0]), (double)(b[4] - b[1]), (double)(b[5] - b[2]),
           rcp_thousands(map.triangle_count, n1, sizeof n1), 1e3 * w.build_s,
           rcp_bytes(w.arena_bytes, n2, sizeof n2));
    printf("          -> %s\n", path);

    /* ---- VLP-16 on a robot: two stops in the hall, sensor 1 m above the floor ---- */
    lidar_poses[0] = pose_yaw_pitch(0.0f, -1.5f, 1.0f, 0.0, 0.0);
    lidar_poses[1] = pose_yaw_pitch(-4.0f, 2.5f, 1.0f, 0.5, 0.0);
    {
        size_t n = 2u * (size_t)li.rays_per_scan;
        rc_results res = rc_results_default();
        rcu_scan_view view;
        rcp_image_options io;
        l_points = (float *)malloc(n * 3u * sizeof(float));
        l_normals = (float *)malloc(n * 3u * sizeof(float));
        l_ranges = (float *)malloc(n * sizeof(float));
        l_hits = (uint8_t *)malloc(n);
        if (!l_points || !l_normals || !l_ranges || !l_hits) {
            rcp_fail(cmd, "out of memory");
            goto done;
        }
        res.attributes = RC_ATTR_HITS | RC_ATTR_RANGES | RC_ATTR_POINTS | RC_ATTR_NORMALS;
        res.hits = l_hits;
        res.ranges = l_ranges;
        res.points = l_points;
        res.normals = l_normals;
        res.capacity = n;
        if ((st = rc_simulate(w.ctx, w.scene, w.sensors[0], lidar_poses, 2, &res)) != RC_OK) {
            rcp_lib_error(cmd, w.ctx, "rc_simulate", st);
            goto done;
        }
        l_time = time_simulate(w.ctx, w.scene, w.sensors[0], lidar_poses, 2, &res) / 2.0;
        memset(&view, 0, sizeof view);
        view.points = l_points;
        view.hits = l_hits;
        view.ranges = l_ranges;
        view.normals = l_normals;
        view.rays_per_scan = li.rays_per_scan;
        view.columns = li.columns;
        view.pose_count = 2;
        view.poses = lidar_poses;
        view.sensor_to_base = &lref.mount;
        if (rcu_cloud_append(&lcloud, &view) != 0) {
            rcp_fail(cmd, "%s", rcu_last_error());
            goto done;
        }
        printf("\n  VLP-16  2 scans x %s rays: %s returns (%.1f%%), %.3f ms a scan (%s scans/s)\n",
               rcp_thousands(li.rays_per_scan, n1, sizeof n1), rcp_thousands(lcloud.count, n2, sizeof n2),
               100.0 * (double)lcloud.count / (double)n, 1e3 * l_time,
               rcp_thousands((uint64_t)(1.0 / l_time + 0.5), n3, sizeof n3));
        join(path, sizeof path, dir, "vlp16_scan.ply");
        if (rcu_cloud_write_ply(path, &lcloud, 0) != 0) goto file_error;
        printf("          -> %s\n", path);
        join(path, sizeof path, dir, "vlp16_scan.pcd");
        if (rcu_cloud_write_pcd(path, &lcloud, 0) != 0) goto file_error;
        printf("          -> %s\n", path);
        rcp_image_options_for(li.model, li.rows, li.columns, &io);
        io.row_scale = 8;
        join(path, sizeof path, dir, "vlp16_range.png");
        if (rcp_range_image_write(path, l_ranges, li.rows, li.columns, &io, img_path, sizeof img_path) != 0)
            goto file_error;
        printf("          -> %s (%u x %u, turbo colours: near blue, far red; black = no return)\n",
               img_path, li.columns, li.rows * 8u);
    }

    /* ---- D435 looking west across the hall, tilted down a little ---- */
    cam_pose = pose_yaw_pitch(-1.2f, -3.2f, 1.3f, 3.14159265358979 - 0.35, 0.10);
    {
        size_t n = ci.rays_per_scan, k;
        rc_results res = rc_results_default();
        rcu_scan_view view;
        rcp_image_options io;
        c_points = (float *)malloc(n * 3u * sizeof(float));
        c_ranges = (float *)malloc(n * sizeof(float));
        c_depth = (float *)malloc(n * sizeof(float));
        c_hits = (uint8_t *)malloc(n);
        if (!c_points || !c_ranges || !c_depth || !c_hits) {
            rcp_fail(cmd, "out of memory");
            goto done;
        }
        res.attributes = RC_ATTR_HITS | RC_ATTR_RANGES | RC_ATTR_POINTS;
        res.hits = c_hits;
        res.ranges = c_ranges;
        res.points = c_points;
        res.capacity = n;
        if ((st = rc_simulate(w.ctx, w.scene, w.sensors[1], &cam_pose, 1, &res)) != RC_OK) {
            rcp_lib_error(cmd, w.ctx, "rc_simulate", st);
            goto done;
        }
        c_time = time_simulate(w.ctx, w.scene, w.sensors[1], &cam_pose, 1, &res);
        /* depth (distance along the optical axis), as a depth camera reports it */
        for (k = 0; k < n; k++) {
            double axis = cref.dirs[3u * k + cref.forward_axis];
            c_depth[k] = isfinite(c_ranges[k]) ? (float)(c_ranges[k] * axis) : c_ranges[k];
        }
        memset(&view, 0, sizeof view);
        view.points = c_points;
        view.hits = c_hits;
        view.ranges = c_ranges;
        view.rays_per_scan = ci.rays_per_scan;
        view.columns = ci.columns;
        view.pose_count = 1;
        view.poses = &cam_pose;
        view.sensor_to_base = &cref.mount;
        if (rcu_cloud_append(&ccloud, &view) != 0) {
            rcp_fail(cmd, "%s", rcu_last_error());
            goto done;
        }
        printf("\n  D435    %u x %u depth: %s returns (%.1f%%), %.2f ms a frame (%s frames/s)\n",
               ci.columns, ci.rows, rcp_thousands(ccloud.count, n2, sizeof n2),
               100.0 * (double)ccloud.count / (double)n, 1e3 * c_time,
               rcp_thousands((uint64_t)(1.0 / c_time + 0.5), n3, sizeof n3));
        rcp_image_options_for(ci.model, ci.rows, ci.columns, &io);
        io.lo = 0.0f; /* a fixed 0..range_max scale reads like a depth camera's viewer */
        io.hi = (float)cref.range_max;
        join(path, sizeof path, dir, "d435_depth.png");
        if (rcp_range_image_write(path, c_depth, ci.rows, ci.columns, &io, img_path, sizeof img_path) != 0)
            goto file_error;
        printf("          -> %s (0..%.0f m; black = beyond range)\n", img_path, cref.range_max);
        join(path, sizeof path, dir, "d435_cloud.ply");
        if (rcu_cloud_write_ply(path, &ccloud, 0) != 0) goto file_error;
        printf("          -> %s\n", path);
    }
    if (!rcp_range_image_has_png())
        printf("\n  (built without libpng: the images are PPM files instead of PNG)\n");
    printf("\nOpen the .ply files together in MeshLab or CloudCompare; try\n"
           "  rangecast simulate --map %s/demo_map.ply --pose 0,0,1 --sensor os1-64 -o os1.ply --image os1.png\n"
           "  rangecast bench --triangles 100k\n", dir);
    rc = RCP_EXIT_OK;
    goto done;
file_error:
    rcp_fail(cmd, "%s", rcu_last_error());
done:
    rcp_world_destroy(&w);
    rcu_preset_rays_free(&lref);
    rcu_preset_rays_free(&cref);
    rcu_cloud_free(&lcloud);
    rcu_cloud_free(&ccloud);
    free(l_points);
    free(l_ranges);
    free(l_normals);
    free(l_hits);
    free(c_points);
    free(c_ranges);
    free(c_depth);
    free(c_hits);
    rcu_mesh_free(&map);
    return rc;
}
