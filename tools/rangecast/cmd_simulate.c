/* rangecast simulate: a sensor at one or many poses in a mesh map -> a point
 * cloud of every return, written a batch of scans at a time (and a range
 * image of the first scan). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cloud.h"
#include "mesh_load.h"
#include "ouster_frame.h"
#include "ouster_json.h"
#include "poses.h"
#include "range_image.h"
#include "reference.h"
#include "scan_names.h"
#include "tool.h"
#include "util.h"

#define SIM_CHUNK_BYTES ((size_t)128 << 20) /* result buffers per rc_simulate call */

static void usage(FILE *f)
{
    fprintf(f,
        "Usage: rangecast simulate --map FILE (--poses FILE | --pose x,y,z,qx,qy,qz,qw) -o OUT [options]\n"
        "\n"
        "Simulates a sensor at each pose (base-to-map) and writes every valid return\n"
        "as one point cloud.\n"
        "\n"
        "Options:\n"
        "  --map FILE          mesh map (%s)\n"
        "  --poses FILE        raw poses: float32 LE x y z qx qy qz qw per pose, or a TUM\n"
        "                      trajectory (.tum/.txt: lines 'timestamp x y z qx qy qz qw')\n"
        "  --pose P            one pose, x,y,z,qx,qy,qz,qw (quaternion optional: x,y,z)\n"
        "  --sensor NAME       vlp16 (default), vlp16-360, os1-64, d435, livox-mid40,\n"
        "                      ust-10lx, lds-01 (2-D scanners);\n"
        "                      ouster:FILE.json: an Ouster unit from its metadata (rc_ouster_rays: each\n"
        "                      ray from its beam origin; rows are beams, columns measurement ids;\n"
        "                      range is from the beam origin, 0.3 .. 120 m). Columns outside the\n"
        "                      metadata's column_window return nothing, and --image is destaggered\n"
        "                      by its pixel_shift_by_row (as Ouster's SDK shows a frame)\n"
        "  --backend B         auto (default), bvh, embree, vulkan\n"
        "  --threads N         worker threads, 0 = all CPUs (default)\n"
        "  --mesh M            reference (default): the map's arrays used in place; copy:\n"
        "                      copied into the arena (RC_MESH_COPY), its vertices renumbered\n"
        "                      in the tree's leaf order (faster on a map exported in a poor\n"
        "                      vertex order)\n"
        "  --poses-per-call N  poses an rc_simulate call takes, each call's returns then\n"
        "                      written to OUT (default: as many as 128 MiB of results hold,\n"
        "                      321 VLP-16 scans), so a trajectory need not fit in memory\n"
        "  -o, --output OUT    .ply or .pcd (binary unless --ascii); a name with one %%d or\n"
        "                      %%0Nd (scans/scan_%%05d.pcd) writes a file a scan, the pose's\n"
        "                      index (from 0) in its name\n"
        "  --ascii             write ascii PLY/PCD\n"
        "  --frame F           sensor (default: each scan in its own sensor frame) or map\n"
        "  --fields LIST       extra per-point fields, comma-separated: range, intensity, ring\n"
        "  --image OUT.png     range image of the first scan (colour; inf black, -inf white)\n"
        "  --image-mode M      color (default) or gray16 (millimetres, 0 = no return)\n"
        "  --noise SIGMA       Gaussian range noise, metres (rc_sensor_set_noise): a\n"
        "                      return's range r becomes r + MEAN + SIGMA * r^K * N(0,1)\n"
        "  --noise-mean MEAN   range bias, metres (default 0)\n"
        "  --noise-exponent K  0 (default): constant; 1: grows with range; 2: stereo depth\n"
        "  --dropout P         probability in [0, 1] that a return is lost\n"
        "  --seed S            the noise's seed (default 0): the same seed, the same cloud\n"
        "  -h, --help          this text\n",
        rcp_mesh_formats());
}

typedef struct sim_args {
    const char *map, *poses_path, *out, *image, *sensor_name;
    const char *ouster_path; /* --sensor ouster:FILE, else NULL */
    int have_pose, ascii, map_frame;
    int per_scan; /* -o is a pattern (scan_names.h): a file a scan */
    rc_pose pose;
    uint32_t preset, backend, threads, fields, image_mode;
    uint32_t poses_per_call; /* 0: by SIM_CHUNK_BYTES */
    rc_noise_desc noise; /* all zero: none */
} sim_args;

/* A number for a noise option (its range is the library's to judge). */
static int parse_noise_value(const char *cmd, const char *name, const char *v, float *out)
{
    if (rcp_parse_float(v, out) == 0) return 0;
    rcp_usage_error(cmd, "%s: expected a number, got '%s'", name, v);
    return -1;
}

/* A decimal uint64 and nothing else (no sign, no suffix). */
static int parse_u64(const char *s, uint64_t *out)
{
    char *end = NULL;
    unsigned long long v;
    if (!s || *s < '0' || *s > '9') return -1;
    errno = 0;
    v = strtoull(s, &end, 10);
    if (errno != 0 || *end != '\0') return -1;
    *out = (uint64_t)v;
    return 0;
}

static int parse_fields(const char *s, uint32_t *fields)
{
    *fields = 0;
    while (*s) {
        size_t n = strcspn(s, ",");
        if (n == 5 && strncmp(s, "range", 5) == 0) *fields |= RCU_CLOUD_RANGE;
        else if (n == 9 && strncmp(s, "intensity", 9) == 0) *fields |= RCU_CLOUD_INTENSITY;
        else if (n == 4 && strncmp(s, "ring", 4) == 0) *fields |= RCU_CLOUD_RING;
        else if (n != 0) return -1;
        s += n;
        if (*s == ',') s++;
    }
    return 0;
}

static int parse_args(int argc, char **argv, sim_args *a)
{
    const char *cmd = "simulate";
    int i, r;
    rcp_order_room = 1; /* calls of many scans: room for ordered runs */
    memset(a, 0, sizeof *a);
    a->sensor_name = "vlp16";
    a->noise = rc_noise_desc_default();
    for (i = 1; i < argc; i++) {
        const char *v = NULL;
        if (rcp_is_help(argv[i])) {
            usage(stdout);
            exit(RCP_EXIT_OK);
        }
#define OPT(name) ((r = rcp_opt(argc, argv, &i, name, &v)) != 0)
        if (OPT("--map")) { if (r < 0) return -1; a->map = v; }
        else if (OPT("--poses")) { if (r < 0) return -1; a->poses_path = v; }
        else if (OPT("--pose")) {
            float p[7];
            if (r < 0) return -1;
            if (rcp_parse_floats(v, p, 7) == 0) {
                memcpy(a->pose.position, p, sizeof a->pose.position);
                memcpy(a->pose.orientation, p + 3, sizeof a->pose.orientation);
            } else if (rcp_parse_floats(v, p, 3) == 0) {
                a->pose = rc_pose_identity();
                memcpy(a->pose.position, p, sizeof a->pose.position);
            } else {
                return rcp_usage_error(cmd, "--pose: expected x,y,z,qx,qy,qz,qw or x,y,z, got '%s'", v), -1;
            }
            {
                double q2 = 0.0;
                int k;
                for (k = 0; k < 4; k++) q2 += (double)a->pose.orientation[k] * a->pose.orientation[k];
                if (fabs(sqrt(q2) - 1.0) > 1e-3)
                    return rcp_usage_error(cmd, "--pose: the quaternion (%g, %g, %g, %g) has norm %g, not 1",
                                           (double)a->pose.orientation[0], (double)a->pose.orientation[1],
                                           (double)a->pose.orientation[2], (double)a->pose.orientation[3],
                                           sqrt(q2)), -1;
            }
            a->have_pose = 1;
        } else if (OPT("--sensor")) {
            if (r < 0) return -1;
            if (strncmp(v, RCP_OUSTER_PREFIX, strlen(RCP_OUSTER_PREFIX)) == 0) {
                a->ouster_path = v + strlen(RCP_OUSTER_PREFIX);
                a->preset = 0;
            } else if (rcp_parse_sensor(cmd, v, &a->preset) != 0) {
                return -1;
            } else {
                a->ouster_path = NULL;
            }
            a->sensor_name = v;
        } else if (OPT("--backend")) {
            if (r < 0 || rcp_parse_backend(cmd, v, &a->backend) != 0) return -1;
        } else if (OPT("--mesh")) {
            if (r < 0 || rcp_parse_mesh_mode(cmd, v) != 0) return -1;
        } else if (OPT("--poses-per-call")) {
            if (r < 0) return -1;
            if (rcp_parse_u32(v, &a->poses_per_call) != 0 || a->poses_per_call == 0)
                return rcp_usage_error(cmd, "--poses-per-call: expected a count >= 1, got '%s'", v), -1;
        } else if (OPT("--threads")) {
            if (r < 0) return -1;
            if (rcp_parse_u32(v, &a->threads) != 0 || a->threads > RC_MAX_THREADS)
                return rcp_usage_error(cmd, "--threads: expected 0..%u, got '%s'", RC_MAX_THREADS, v), -1;
        } else if (OPT("-o") || (r == 0 && OPT("--output"))) {
            if (r < 0) return -1;
            a->out = v;
        } else if (strcmp(argv[i], "--ascii") == 0) {
            a->ascii = 1;
        } else if (OPT("--frame")) {
            if (r < 0) return -1;
            if (strcmp(v, "map") == 0) a->map_frame = 1;
            else if (strcmp(v, "sensor") == 0) a->map_frame = 0;
            else return rcp_usage_error(cmd, "--frame: expected sensor or map, got '%s'", v), -1;
        } else if (OPT("--fields")) {
            if (r < 0) return -1;
            if (parse_fields(v, &a->fields) != 0)
                return rcp_usage_error(cmd, "--fields: expected a list of range, intensity, ring; got '%s'", v), -1;
        } else if (OPT("--image")) {
            if (r < 0) return -1;
            a->image = v;
        } else if (OPT("--noise")) {
            if (r < 0 || parse_noise_value(cmd, "--noise", v, &a->noise.sigma) != 0) return -1;
        } else if (OPT("--noise-mean")) {
            if (r < 0 || parse_noise_value(cmd, "--noise-mean", v, &a->noise.mean) != 0) return -1;
        } else if (OPT("--noise-exponent")) {
            if (r < 0 || parse_noise_value(cmd, "--noise-exponent", v, &a->noise.sigma_exponent) != 0) return -1;
        } else if (OPT("--dropout")) {
            if (r < 0 || parse_noise_value(cmd, "--dropout", v, &a->noise.dropout) != 0) return -1;
        } else if (OPT("--seed")) {
            if (r < 0) return -1;
            if (parse_u64(v, &a->noise.seed) != 0)
                return rcp_usage_error(cmd, "--seed: expected a decimal number 0..2^64-1, got '%s'", v), -1;
        } else if (OPT("--image-mode")) {
            if (r < 0) return -1;
            if (strcmp(v, "color") == 0 || strcmp(v, "colour") == 0) a->image_mode = RCP_IMAGE_COLOR;
            else if (strcmp(v, "gray16") == 0 || strcmp(v, "grey16") == 0) a->image_mode = RCP_IMAGE_GRAY16;
            else return rcp_usage_error(cmd, "--image-mode: expected color or gray16, got '%s'", v), -1;
        } else {
            return rcp_usage_error(cmd, "unknown argument '%s'", argv[i]), -1;
        }
#undef OPT
    }
    if (!a->map) return rcp_usage_error(cmd, "--map FILE is required"), -1;
    if (!a->poses_path && !a->have_pose) return rcp_usage_error(cmd, "give --poses FILE or --pose x,y,z,qx,qy,qz,qw"), -1;
    if (a->poses_path && a->have_pose) return rcp_usage_error(cmd, "give either --poses or --pose, not both"), -1;
    if (!a->out) return rcp_usage_error(cmd, "-o OUT.ply|OUT.pcd is required"), -1;
    {
        char ext[8];
        rcu_path_extension(a->out, ext, sizeof ext);
        if (strcmp(ext, "ply") != 0 && strcmp(ext, "pcd") != 0)
            return rcp_usage_error(cmd, "-o %s: the point cloud must be .ply or .pcd", a->out), -1;
        if ((a->per_scan = rcu_scan_pattern(a->out)) < 0) return rcp_usage_error(cmd, "-o %s", rcu_last_error()), -1;
    }
    if (a->preset == 0 && !a->ouster_path) a->preset = rc_preset_from_name(a->sensor_name);
    return 0;
}

/* A file a scan (-o with a pattern): the batch's scans, poses first .. first
 * + view->pose_count - 1, each to the name its pose index gives; adds their
 * returns to *returns. 0, or -1 with rcu_last_error() (the failed file is not
 * left behind; the scans' files before it are whole). */
static int write_scans(const sim_args *a, const rcu_scan_view *view, uint32_t first, size_t *returns)
{
    char name[4096];
    uint32_t s;
    for (s = 0; s < view->pose_count; ++s) {
        const size_t at = (size_t)s * view->rays_per_scan;
        rcu_scan_view one = *view;
        rcu_cloud_stream st;
        one.pose_count = 1;
        one.points = view->points + 3u * at;
        one.hits = view->hits ? view->hits + at : NULL;
        one.ranges = view->ranges ? view->ranges + at : NULL;
        one.normals = view->normals ? view->normals + 3u * at : NULL;
        one.poses = view->poses ? view->poses + s : NULL;
        if (rcu_scan_name(a->out, first + s, name, sizeof name) != 0) return -1;
        if (rcu_cloud_stream_open(&st, name, a->fields, a->ascii) != 0) return -1;
        if (rcu_cloud_stream_append(&st, &one) != 0) {
            rcu_cloud_stream_abort(&st);
            return -1;
        }
        *returns += st.count;
        if (rcu_cloud_stream_close(&st) != 0) return -1;
    }
    return 0;
}

/* Writes the range image of one scan, its file's name into written (the
 * PPM's where the program has no libpng); 0 or RCP_EXIT_FAIL (message
 * printed). */
static int write_image(const char *cmd, const char *path, uint32_t preset, const rc_sensor_info *si,
                       const float *ranges, uint32_t mode, char *written, size_t written_size)
{
    rcp_image_options io;
    int st;
    rcp_image_options_for(si->model, si->rows, si->columns, &io);
    io.mode = mode;
    if (si->model == RC_SENSOR_O1DN && si->rows <= 1 && mode == RCP_IMAGE_COLOR) {
        rcu_preset_rays ref;
        if (rcu_preset_rays_f64(preset, &ref) != 0) return rcp_fail(cmd, "%s", rcu_last_error());
        st = rcp_scatter_image_write(path, ranges, ref.dirs, ref.rays, 640, &io, written, written_size);
        rcu_preset_rays_free(&ref);
    } else {
        st = rcp_range_image_write(path, ranges, si->rows, si->columns, &io, written, written_size);
    }
    if (st != 0) return rcp_fail(cmd, "%s", rcu_last_error());
    if (!rcp_range_image_has_png())
        fprintf(stderr, "rangecast %s: built without libpng: wrote %s instead of %s\n", cmd, written, path);
    return 0;
}

int rcp_cmd_simulate(int argc, char **argv)
{
    const char *cmd = "simulate";
    sim_args a;
    rcu_mesh mesh;
    rc_pose *poses = NULL;
    uint32_t pose_count = 0, rays, chunk, p;
    rcp_world w;
    rc_sensor_info si = rc_sensor_info_default();
    rcu_cloud_stream out;
    int out_open = 0;
    rcu_preset_rays ref;
    rcp_rays ou;
    float *points = NULL, *ranges = NULL, *normals = NULL, *image = NULL;
    uint8_t *hits = NULL;
    double t_sim = 0.0;
    size_t returns = 0;
    int rc = RCP_EXIT_FAIL;
    char n1[32], n2[32];
    char image_written[4096] = ""; /* the image's file once written: a failed run removes it */

    if (parse_args(argc, argv, &a) != 0) return RCP_EXIT_USAGE;
    memset(&w, 0, sizeof w);
    memset(&ref, 0, sizeof ref);
    memset(&ou, 0, sizeof ou);
    if (rcp_mesh_load(a.map, &mesh) != 0) return rcp_fail(cmd, "%s", rcu_last_error());
    if (a.poses_path) {
        if (rcu_poses_read(a.poses_path, &poses, &pose_count) != 0) {
            rcp_fail(cmd, "%s", rcu_last_error());
            goto done;
        }
    } else {
        poses = (rc_pose *)malloc(sizeof *poses);
        if (!poses) goto done;
        poses[0] = a.pose;
        pose_count = 1;
    }
    if (a.ouster_path) {
        rc_rays_desc rd;
        if (rcp_ouster_load(a.ouster_path, &ou) != 0) {
            rcp_fail(cmd, "%s", rcu_last_error());
            goto done;
        }
        rd = rcp_rays_desc(&ou);
        if (rcp_world_create_rays(cmd, a.backend, a.threads, &mesh, RC_SENSOR_ONDN, &rd, &w) != RCP_EXIT_OK)
            goto done;
    } else if (rcp_world_create(cmd, a.backend, a.threads, &mesh, &a.preset, 1, &w) != RCP_EXIT_OK) {
        goto done;
    }
    {
        /* the library judges the values: its message names the field */
        const rc_status st = rc_sensor_set_noise(w.sensors[0], &a.noise);
        if (st != RC_OK) {
            rc = rcp_usage_error(cmd, "--noise/--noise-mean/--noise-exponent/--dropout: %s",
                                 rc_context_last_error(w.ctx));
            goto done;
        }
    }
    rc_sensor_get_info(w.sensors[0], &si);
    rays = si.rays_per_scan;
    if ((a.ouster_path ? rcu_rays_f64(ou.origins, ou.dirs, ou.count, ou.range_min, ou.range_max, &ref)
                       : rcu_preset_rays_f64(a.preset, &ref)) != 0) {
        rcp_fail(cmd, "%s", rcu_last_error());
        goto done;
    }

    chunk = (uint32_t)(SIM_CHUNK_BYTES / ((size_t)rays * 29u));
    if (chunk == 0) chunk = 1;
    if (a.poses_per_call) chunk = a.poses_per_call;
    if (chunk > pose_count) chunk = pose_count;
    /* results a call: 29 bytes a ray at most (points, normals, range, hit) */
    if ((uint64_t)chunk * rays * 29u > (uint64_t)(SIZE_MAX / 2u)) {
        rcp_fail(cmd, "--poses-per-call %u: the results of that many scans do not fit in this machine's memory",
                 chunk);
        goto done;
    }
    points = (float *)malloc((size_t)chunk * rays * 3u * sizeof(float));
    ranges = (float *)malloc((size_t)chunk * rays * sizeof(float));
    hits = (uint8_t *)malloc((size_t)chunk * rays);
    if (a.fields & RCU_CLOUD_INTENSITY) normals = (float *)malloc((size_t)chunk * rays * 3u * sizeof(float));
    if (!points || !ranges || !hits || ((a.fields & RCU_CLOUD_INTENSITY) && !normals)) {
        rcp_fail(cmd, "out of memory for %u scans of results", chunk);
        goto done;
    }
    /* the cloud goes to the file a batch at a time: a long trajectory's
     * scans need not fit in memory */
    if (!a.per_scan) {
        if (rcu_cloud_stream_open(&out, a.out, a.fields, a.ascii) != 0) {
            rcp_fail(cmd, "%s", rcu_last_error());
            goto done;
        }
        out_open = 1;
    }
    for (p = 0; p < pose_count; p += chunk) {
        uint32_t n = pose_count - p < chunk ? pose_count - p : chunk;
        rc_results res = rc_results_default();
        rcu_scan_view view;
        rc_status st;
        double t0;
        res.attributes = RC_ATTR_HITS | RC_ATTR_RANGES | RC_ATTR_POINTS | (normals ? RC_ATTR_NORMALS : 0u);
        res.hits = hits;
        res.ranges = ranges;
        res.points = points;
        res.normals = normals;
        res.capacity = (uint64_t)n * rays;
        t0 = rcu_now();
        if ((st = rc_simulate(w.ctx, w.scene, w.sensors[0], poses + p, n, &res)) != RC_OK) {
            rcp_lib_error(cmd, w.ctx, "rc_simulate", st);
            goto done;
        }
        t_sim += rcu_now() - t0;
        if (a.ouster_path) { /* the frame's column window: no data outside it */
            uint32_t s;
            for (s = 0; s < n; ++s)
                rcu_ouster_mask_window(ou.height, ou.width, ou.window_start, ou.window_end, hits + (size_t)s * rays,
                                       ranges + (size_t)s * rays, points + (size_t)s * rays * 3u);
        }
        memset(&view, 0, sizeof view);
        view.points = points;
        view.hits = hits;
        view.ranges = ranges;
        view.normals = normals;
        view.rays_per_scan = rays;
        view.columns = si.columns;
        view.pose_count = n;
        view.poses = a.map_frame ? poses + p : NULL;
        view.sensor_to_base = &ref.mount;
        if (a.per_scan) {
            if (write_scans(&a, &view, p, &returns) != 0) {
                rcp_fail(cmd, "%s", rcu_last_error());
                goto done;
            }
        } else if (rcu_cloud_stream_append(&out, &view) != 0) {
            rcp_fail(cmd, "%s", rcu_last_error());
            goto done;
        }
        /* several batches on a terminal: how far it got, rewritten in place */
        if (pose_count > chunk && isatty(STDERR_FILENO))
            fprintf(stderr, "\rrangecast simulate: %s of %s scans%s", rcp_thousands(p + n, n1, sizeof n1),
                    rcp_thousands(pose_count, n2, sizeof n2), p + n == pose_count ? "\n" : "");
        if (p == 0 && a.image) {
            const float *shown = ranges;
            if (a.ouster_path && ou.pixel_shift) { /* destaggered, as the SDK shows a frame */
                image = (float *)malloc((size_t)rays * sizeof(float));
                if (!image) {
                    rcp_fail(cmd, "out of memory for the destaggered image");
                    goto done;
                }
                rcu_ouster_destagger(ranges, image, ou.height, ou.width, ou.pixel_shift);
                shown = image;
            }
            if (write_image(cmd, a.image, a.preset, &si, shown, a.image_mode, image_written, sizeof image_written) !=
                0) {
                image_written[0] = '\0';
                goto done;
            }
        }
    }
    if (out_open) {
        returns = out.count;
        out_open = 0;
        if (rcu_cloud_stream_close(&out) != 0) {
            rcp_fail(cmd, "%s", rcu_last_error());
            goto done;
        }
    }
    if (pose_count > 1 && !a.map_frame && !a.per_scan)
        fprintf(stderr, "rangecast simulate: note: %u scans written each in its own sensor frame "
                        "(--frame map places them in the map)\n", pose_count);
    printf("%s: %u scan%s x %s rays, %s returns (%.1f%%), simulated in %.3f s (%.0f scans/s, %s, %u threads) -> %s",
           a.sensor_name, pose_count, pose_count == 1 ? "" : "s", rcp_thousands(rays, n1, sizeof n1),
           rcp_thousands(returns, n2, sizeof n2),
           100.0 * (double)returns / ((double)pose_count * rays), t_sim,
           t_sim > 0 ? pose_count / t_sim : 0.0, rc_backend_name(w.backend), w.threads, a.out);
    if (a.per_scan) printf(" (%u files)", pose_count);
    if (a.image) printf(", %s", a.image);
    printf("\n");
    rc = RCP_EXIT_OK;
done:
    /* a failed run leaves none of its outputs: the image written before
     * the cloud failed goes too (a file a scan: those before it are whole) */
    if (rc != RCP_EXIT_OK && image_written[0]) rcu_remove_partial(image_written);
    rcp_world_destroy(&w);
    rcu_preset_rays_free(&ref);
    rcp_rays_free(&ou);
    if (out_open) rcu_cloud_stream_abort(&out);
    free(points);
    free(ranges);
    free(image);
    free(hits);
    free(normals);
    free(poses);
    rcu_mesh_free(&mesh);
    return rc;
}
