/* The raw pose files and point clouds of the `rangecast` program
 * (tools/common/poses.c, cloud.c): formats users' scripts read and write, so
 * their bytes are pinned here. Pose files round-trip bit for bit and every
 * malformed one is refused with a message naming the file and the pose; the
 * standard random poses are the same numbers on every platform (this runner
 * also runs under qemu for aarch64 and armhf); clouds keep exactly the valid
 * returns, in the frame asked for, with their fields in PCD and PLY. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cloud.h"
#include "ouster_frame.h"
#include "poses.h"
#include "scan_names.h"
#include "util.h"

static void write_bytes(const char *path, const void *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, size, f), size);
    assert_int_equal(fclose(f), 0);
}

/* Whole file into a malloc'd buffer. */
static unsigned char *slurp(const char *path, size_t *size)
{
    unsigned char *data = NULL;
    assert_int_equal(rcu_read_file(path, &data, size), 0);
    return data;
}

static void expect_message(const char *part)
{
    if (!strstr(rcu_last_error(), part)) {
        print_error("message '%s' lacks '%s'\n", rcu_last_error(), part);
        fail();
    }
}

static void test_pose_file_round_trip(void **state)
{
    const char *path = "test_tool_files_poses.bin";
    rc_pose in[5], *out = NULL;
    uint32_t count = 0;
    unsigned char *raw;
    size_t size;
    (void)state;
    rcu_poses_random(5, 10.0f, 42, in);
    assert_int_equal(rcu_poses_write(path, in, 5), 0);
    /* 28 bytes a pose, float32 little-endian x y z qx qy qz qw */
    raw = slurp(path, &size);
    assert_int_equal(size, 5 * 28);
    assert_true(rcu_load_f32le(raw + 28 + 4) == in[1].position[1]);
    assert_true(rcu_load_f32le(raw + 28 + 24) == in[1].orientation[3]);
    free(raw);
    assert_int_equal(rcu_poses_read(path, &out, &count), 0);
    assert_int_equal(count, 5);
    assert_memory_equal(out, in, sizeof in);
    free(out);
    remove(path);
}

static void test_pose_file_errors(void **state)
{
    const char *path = "test_tool_files_bad.bin";
    unsigned char rec[3 * 28];
    rc_pose p[3], *out = (rc_pose *)0x1;
    uint32_t count = 77, k;
    float nan_value = NAN;
    (void)state;
    rcu_poses_random(3, 10.0f, 1, p);
    for (k = 0; k < 3; ++k) {
        uint32_t j;
        for (j = 0; j < 3; ++j) rcu_store_f32le(rec + 28 * k + 4 * j, p[k].position[j]);
        for (j = 0; j < 4; ++j) rcu_store_f32le(rec + 28 * k + 12 + 4 * j, p[k].orientation[j]);
    }
    assert_int_equal(rcu_poses_read("no_such_poses.bin", &out, &count), -1);
    expect_message("no_such_poses.bin");
    write_bytes(path, rec, 0);
    assert_int_equal(rcu_poses_read(path, &out, &count), -1);
    expect_message("empty pose file");
    write_bytes(path, rec, 55);
    assert_int_equal(rcu_poses_read(path, &out, &count), -1);
    expect_message("size 55 bytes is not a multiple of 28");
    expect_message("27 bytes left over");
    /* pose 2's z is NaN */
    rcu_store_f32le(rec + 2 * 28 + 8, nan_value);
    write_bytes(path, rec, sizeof rec);
    assert_int_equal(rcu_poses_read(path, &out, &count), -1);
    expect_message("pose 2 (byte offset 56) has a NaN or infinite value");
    /* pose 1's quaternion doubled: norm 2 */
    rcu_store_f32le(rec + 2 * 28 + 8, 0.0f);
    for (k = 0; k < 4; ++k) rcu_store_f32le(rec + 28 + 12 + 4 * k, 2.0f * p[1].orientation[k]);
    write_bytes(path, rec, sizeof rec);
    assert_int_equal(rcu_poses_read(path, &out, &count), -1);
    expect_message("pose 1 (byte offset 28)");
    expect_message("has norm 2");
    /* nothing was handed back by any failure */
    assert_true(out == (rc_pose *)0x1);
    assert_int_equal(count, 77);
    remove(path);
    assert_int_equal(rcu_poses_write("no_such_dir/p.bin", p, 3), -1);
    expect_message("no_such_dir/p.bin");
}

/* A text file of the given contents. */
static void write_text(const char *path, const char *text) { write_bytes(path, (const unsigned char *)text, strlen(text)); }

/* TUM trajectories (.tum/.txt, tum.h): written and read back bit for bit;
 * comments, blank lines, CRLF, tabs and commas read; each bad line named by
 * its number, and nothing handed back. */
static void test_pose_file_tum(void **state)
{
    const char *path = "test_tool_files.tum";
    rc_pose p[5], *out = NULL;
    uint32_t count = 0, k;
    (void)state;
    rcu_poses_random(5, 10.0f, 3, p);
    assert_int_equal(rcu_poses_write(path, p, 5), 0);
    assert_int_equal(rcu_poses_read(path, &out, &count), 0);
    assert_int_equal(count, 5);
    assert_memory_equal(out, p, sizeof p);
    free(out);

    write_text("test_tool_files.txt", "# time x y z qx qy qz qw\r\n\r\n"
                                      "1.5 1 -2 3.25 0 0 0 1\r\n"
                                      "  \t# a comment\n"
                                      "1.6,0.5,0,0,0,0,0.70710678,0.70710678\n"
                                      "1.7\t4 5 6 1 0 0 0");
    assert_int_equal(rcu_poses_read("test_tool_files.txt", &out, &count), 0);
    assert_int_equal(count, 3);
    assert_true(out[0].position[0] == 1.0f && out[0].position[1] == -2.0f && out[0].position[2] == 3.25f);
    assert_true(out[0].orientation[3] == 1.0f);
    assert_true(out[1].position[0] == 0.5f && out[1].orientation[2] == 0.70710678f);
    assert_true(out[2].position[2] == 6.0f && out[2].orientation[0] == 1.0f);
    free(out);
    remove("test_tool_files.txt");

    out = (rc_pose *)0x1;
    count = 77;
    write_text(path, "# header\n1 0 0 0 0 0 0 1\n2 0 0 0 0 0 1\n");
    assert_int_equal(rcu_poses_read(path, &out, &count), -1);
    expect_message("test_tool_files.tum:3: 7 numbers (expected 8");
    write_text(path, "1 0 0 0 0 0 0 1 9\n");
    assert_int_equal(rcu_poses_read(path, &out, &count), -1);
    expect_message(":1: more than 8 numbers");
    write_text(path, "1 0 0 x 0 0 0 1\n");
    assert_int_equal(rcu_poses_read(path, &out, &count), -1);
    expect_message(":1: not a number");
    write_text(path, "\n1 0 nan 0 0 0 0 1\n");
    assert_int_equal(rcu_poses_read(path, &out, &count), -1);
    expect_message(":2: value 3 is not finite");
    write_text(path, "1 0 1e39 0 0 0 0 1\n");
    assert_int_equal(rcu_poses_read(path, &out, &count), -1);
    expect_message(":1: value 3 is not finite in float");
    write_text(path, "1 0 0 0 0 0 0 2\n");
    assert_int_equal(rcu_poses_read(path, &out, &count), -1);
    expect_message(":1: quaternion (0, 0, 0, 2) has norm 2");
    write_text(path, "# only a comment\n\n");
    assert_int_equal(rcu_poses_read(path, &out, &count), -1);
    expect_message("no pose");
    for (k = 0; k < 2; ++k) {
        /* a raw pose file misnamed .tum: its bytes are no text */
        unsigned char raw[28] = {0};
        write_bytes(path, raw, k ? sizeof raw : 0);
        assert_int_equal(rcu_poses_read(path, &out, &count), -1);
        expect_message(k ? "NUL byte" : "no pose");
    }
    assert_true(out == (rc_pose *)0x1);
    assert_int_equal(count, 77);
    remove(path);
    assert_int_equal(rcu_poses_write("no_such_dir/p.tum", p, 3), -1);
    expect_message("no_such_dir/p.tum");
}

/* The benchmark's poses (`rangecast gen --poses`, bench without --poses) are
 * part of its definition: the first three of seed 1, as x86-64 computed them
 * when the workload was fixed. Positions come from integer arithmetic and
 * must match exactly; orientations use cos/sin, so one float ulp is allowed
 * between C libraries. */
static void test_standard_poses_pinned(void **state)
{
    static const float want[3][7] = {
        {4.05843687f, 0.408732384f, 1.48211396f, -0.737599015f, -0.254202813f, 0.490831554f, 0.387831122f},
        {8.65545368f, 3.3819356f, 1.99866819f, 0.160215199f, 0.289462984f, 0.0512048118f, -0.942295253f},
        {-0.0705245957f, 2.21584296f, -3.00467157f, 0.749764204f, 0.182791561f, 0.413036346f, -0.483572006f}};
    rc_pose p[3];
    int i, k;
    (void)state;
    rcu_poses_random(3, 10.0f, 1, p);
    for (i = 0; i < 3; ++i) {
        double norm2 = 0.0;
        for (k = 0; k < 3; ++k) assert_true(p[i].position[k] == want[i][k]);
        for (k = 0; k < 4; ++k) {
            assert_true(fabsf(p[i].orientation[k] - want[i][3 + k]) <= 1.2e-7f);
            norm2 += (double)p[i].orientation[k] * p[i].orientation[k];
        }
        assert_true(fabs(norm2 - 1.0) < 1e-6);
        assert_true(p[i].position[0] * p[i].position[0] + p[i].position[1] * p[i].position[1] +
                        p[i].position[2] * p[i].position[2] <=
                    100.0f);
    }
}

/* Two scans of four rays: ray 1 of scan 0 and ray 3 of scan 1 are misses
 * (hit 0, NaN point), the rest returns at known points; two columns, so rays
 * 2 and 3 are ring 1. */
static const float SCAN_POINTS[8][3] = {{1, 0, 0}, {NAN, NAN, NAN}, {0, 2, 0}, {0, 0, -3},
                                        {4, 0, 0}, {0, 0, 5}, {3, 4, 0}, {NAN, NAN, NAN}};
static const uint8_t SCAN_HITS[8] = {1, 0, 1, 1, 1, 1, 1, 0};

static void scan_view(rcu_scan_view *v, const rc_pose *poses)
{
    memset(v, 0, sizeof *v);
    v->points = &SCAN_POINTS[0][0];
    v->hits = SCAN_HITS;
    v->rays_per_scan = 4;
    v->columns = 2;
    v->pose_count = 2;
    v->poses = poses;
}

static void test_cloud_keeps_returns_and_fields(void **state)
{
    static const float normals[8][3] = {{-1, 0, 0}, {0, 0, 0}, {0, -0.6f, 0.8f}, {0, 0, 1},
                                        {-1, 0, 0}, {0, 0, -1}, {0, 0, 1}, {0, 0, 0}};
    rcu_cloud c;
    rcu_scan_view v;
    (void)state;
    scan_view(&v, NULL);
    v.normals = &normals[0][0];
    rcu_cloud_init(&c, RCU_CLOUD_RANGE | RCU_CLOUD_INTENSITY | RCU_CLOUD_RING);
    assert_int_equal(rcu_cloud_append(&c, &v), 0);
    assert_int_equal(c.count, 6);
    /* sensor frame: the points as given, range |p| without ranges */
    assert_true(c.xyz[3] == 0.0f && c.xyz[4] == 2.0f && c.xyz[5] == 0.0f);
    assert_true(c.range[1] == 2.0f && c.range[2] == 3.0f && c.range[5] == 5.0f);
    /* intensity |cos incidence|: 0.6 for ray 2, 1 head on, 0 grazing */
    assert_true(fabsf(c.intensity[1] - 0.6f) < 1e-6f);
    assert_true(c.intensity[0] == 1.0f && c.intensity[5] == 0.0f);
    assert_int_equal(c.ring[0], 0);
    assert_int_equal(c.ring[1], 1);
    assert_int_equal(c.ring[4], 0); /* scan 1, ray 1 */
    assert_int_equal(c.ring[5], 1); /* scan 1, ray 2 */
    rcu_cloud_free(&c);
}

static void test_cloud_map_frame(void **state)
{
    /* scan 1 is moved by (10, 0, 0) and turned 90 degrees about z */
    rc_pose poses[2] = {rc_pose_identity(), rc_pose_identity()};
    const float h = (float)sqrt(0.5);
    rcu_cloud c;
    rcu_scan_view v;
    (void)state;
    poses[1].position[0] = 10.0f;
    poses[1].orientation[2] = h;
    poses[1].orientation[3] = h;
    scan_view(&v, poses);
    rcu_cloud_init(&c, RCU_CLOUD_RANGE);
    assert_int_equal(rcu_cloud_append(&c, &v), 0);
    assert_int_equal(c.count, 6);
    /* (4, 0, 0) turned to (0, 4, 0), then moved */
    assert_true(fabsf(c.xyz[9] - 10.0f) < 1e-5f && fabsf(c.xyz[10] - 4.0f) < 1e-5f && c.xyz[11] == 0.0f);
    /* (3, 4, 0) to (-4, 3, 0) + (10, 0, 0); the range stays the sensor's */
    assert_true(fabsf(c.xyz[15] - 6.0f) < 1e-5f && fabsf(c.xyz[16] - 3.0f) < 1e-5f);
    assert_true(c.range[5] == 5.0f);
    rcu_cloud_free(&c);
}

/* Header lines up to and including `last`, and where the data starts. */
static size_t header_end(const unsigned char *data, size_t size, const char *last)
{
    const size_t n = strlen(last);
    size_t i;
    for (i = 0; i + n <= size; ++i)
        if (memcmp(data + i, last, n) == 0) {
            while (i < size && data[i] != '\n') ++i;
            assert_true(i < size);
            return i + 1;
        }
    fail_msg("no '%s' in the header", last);
    return 0;
}

static void test_cloud_files(void **state)
{
    rcu_cloud c;
    rcu_scan_view v;
    unsigned char *data;
    size_t size, at;
    (void)state;
    scan_view(&v, NULL);
    rcu_cloud_init(&c, RCU_CLOUD_RANGE | RCU_CLOUD_RING);
    assert_int_equal(rcu_cloud_append(&c, &v), 0);

    /* binary PCD: FIELDS x y z range ring, 18 bytes a point, little-endian */
    assert_int_equal(rcu_cloud_write("test_tool_files.pcd", &c, 0), 0);
    data = slurp("test_tool_files.pcd", &size);
    assert_non_null(strstr((const char *)data, "\nFIELDS x y z range ring\nSIZE 4 4 4 4 2\nTYPE F F F F U\n"));
    assert_non_null(strstr((const char *)data, "\nWIDTH 6\nHEIGHT 1\n"));
    assert_non_null(strstr((const char *)data, "\nPOINTS 6\nDATA binary\n"));
    at = header_end(data, size, "DATA binary");
    assert_int_equal(size - at, 6 * 18);
    assert_true(rcu_load_f32le(data + at + 18 * 2 + 8) == -3.0f);  /* point 2's z */
    assert_true(rcu_load_f32le(data + at + 18 * 2 + 12) == 3.0f); /* its range */
    assert_int_equal(data[at + 18 * 2 + 16] | data[at + 18 * 2 + 17] << 8, 1);
    free(data);

    /* ascii PLY: one line a point */
    assert_int_equal(rcu_cloud_write("test_tool_files.ply", &c, 1), 0);
    data = slurp("test_tool_files.ply", &size);
    assert_non_null(strstr((const char *)data, "format ascii 1.0\n"));
    assert_non_null(strstr((const char *)data, "element vertex 6\nproperty float x\nproperty float y\n"
                                               "property float z\nproperty float range\nproperty ushort ring\n"));
    at = header_end(data, size, "end_header");
    assert_string_equal((const char *)data + at, "1 0 0 1 0\n0 2 0 2 1\n0 0 -3 3 1\n4 0 0 4 0\n0 0 5 5 0\n"
                                                 "3 4 0 5 1\n");
    free(data);
    remove("test_tool_files.pcd");
    remove("test_tool_files.ply");

    /* an unknown extension or an unwritable place: a message, no file */
    assert_int_equal(rcu_cloud_write("test_tool_files.xyz", &c, 0), -1);
    expect_message("unknown point cloud format '.xyz'");
    assert_int_equal(rcu_cloud_write("no_such_dir/c.pcd", &c, 0), -1);
    expect_message("no_such_dir/c.pcd");
    rcu_cloud_free(&c);
}

/* 1 when path can be opened (C99 has no access()). */
static int exists(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (f) fclose(f);
    return f != NULL;
}

/* 1 when the two files hold the same bytes. */
static int same_file(const char *a, const char *b)
{
    size_t na, nb;
    unsigned char *da = slurp(a, &na), *db = slurp(b, &nb);
    const int same = na == nb && memcmp(da, db, na) == 0;
    free(da);
    free(db);
    return same;
}

/* A cloud written a batch at a time (rcu_cloud_stream): the two scans as two
 * batches give the file rcu_cloud_write gives for both at once, in each
 * format; the body beside it is gone after close, and an abort or a path
 * that cannot be written leaves nothing. */
static void test_cloud_stream(void **state)
{
    static const char *const names[4] = {"test_stream.pcd", "test_stream.ply", "test_stream.pcd", "test_stream.ply"};
    rcu_cloud c;
    rcu_cloud_stream st;
    rcu_scan_view v, half;
    int k;
    (void)state;
    scan_view(&v, NULL);
    rcu_cloud_init(&c, RCU_CLOUD_RANGE | RCU_CLOUD_RING);
    assert_int_equal(rcu_cloud_append(&c, &v), 0);
    half = v;
    half.pose_count = 1;
    for (k = 0; k < 4; ++k) {
        const int ascii = k >= 2;
        assert_int_equal(rcu_cloud_write(k % 2 ? "test_whole.ply" : "test_whole.pcd", &c, ascii), 0);
        /* both scans as one batch, written at close with no body */
        assert_int_equal(rcu_cloud_stream_open(&st, names[k], c.fields, ascii), 0);
        assert_int_equal(rcu_cloud_stream_append(&st, &v), 0);
        assert_int_equal(rcu_cloud_stream_close(&st), 0);
        assert_true(same_file(names[k], k % 2 ? "test_whole.ply" : "test_whole.pcd"));
        /* a batch a scan: the first through the body */
        assert_int_equal(rcu_cloud_stream_open(&st, names[k], c.fields, ascii), 0);
        assert_int_equal(rcu_cloud_stream_append(&st, &half), 0); /* scan 0 */
        half.points = v.points + 3u * v.rays_per_scan;
        half.hits = v.hits + v.rays_per_scan;
        assert_int_equal(rcu_cloud_stream_append(&st, &half), 0); /* scan 1 */
        half.points = v.points;
        half.hits = v.hits;
        assert_int_equal(st.count, 6);
        assert_int_equal(rcu_cloud_stream_close(&st), 0);
        assert_true(same_file(names[k], k % 2 ? "test_whole.ply" : "test_whole.pcd"));
        assert_false(exists(k % 2 ? "test_stream.ply.body.partial" : "test_stream.pcd.body.partial"));
        remove(names[k]);
    }
    remove("test_whole.pcd");
    remove("test_whole.ply");

    /* a single batch goes straight to the output at close; a second sends
     * the first to the body; an abort then removes both */
    assert_int_equal(rcu_cloud_stream_open(&st, "test_stream.ply", c.fields, 0), 0);
    assert_int_equal(rcu_cloud_stream_append(&st, &v), 0);
    assert_false(exists("test_stream.ply.body.partial"));
    assert_int_equal(rcu_cloud_stream_append(&st, &v), 0);
    assert_true(exists("test_stream.ply.body.partial"));
    rcu_cloud_stream_abort(&st);
    assert_false(exists("test_stream.ply"));
    assert_false(exists("test_stream.ply.body.partial"));
    rcu_cloud_stream_abort(&st); /* a released stream: nothing to do */

    assert_int_equal(rcu_cloud_stream_open(&st, "test_stream.xyz", c.fields, 0), -1);
    expect_message("unknown point cloud format '.xyz'");
    assert_int_equal(rcu_cloud_stream_open(&st, "no_such_dir/c.pcd", c.fields, 0), -1);
    expect_message("no_such_dir/c.pcd");
    rcu_cloud_free(&c);
}

/* Per-scan names (scan_names.h): one %d or %0Nd becomes the index; any
 * other '%' is refused, and a name that does not fit fails. */
static void test_scan_names(void **state)
{
    char name[32];
    (void)state;
    assert_int_equal(rcu_scan_pattern("cloud.pcd"), 0);
    assert_int_equal(rcu_scan_pattern("scans/scan_%05d.pcd"), 1);
    assert_int_equal(rcu_scan_pattern("%d.ply"), 1);
    assert_int_equal(rcu_scan_pattern("a_%s.pcd"), -1);
    expect_message("one %d or %0Nd");
    assert_int_equal(rcu_scan_pattern("a_%d_%d.pcd"), -1);
    assert_int_equal(rcu_scan_pattern("a_%00d.pcd"), -1);
    assert_int_equal(rcu_scan_pattern("a_%5d.pcd"), -1);
    assert_int_equal(rcu_scan_pattern("100%.pcd"), -1);
    assert_int_equal(rcu_scan_name("scans/scan_%05d.pcd", 42, name, sizeof name), 0);
    assert_string_equal(name, "scans/scan_00042.pcd");
    assert_int_equal(rcu_scan_name("%d.ply", 1234567, name, sizeof name), 0);
    assert_string_equal(name, "1234567.ply");
    assert_int_equal(rcu_scan_name("s%02d", 123, name, sizeof name), 0);
    assert_string_equal(name, "s123");
    assert_int_equal(rcu_scan_name("a_long_prefix_%09d.pcd", 1, name, 20), -1);
    expect_message("too long");
    assert_int_equal(rcu_scan_name("plain.pcd", 1, name, sizeof name), -1);
}

/* An Ouster frame: the column window (wrapping or not) and destaggering as
 * the SDK does it, on a 3 x 5 field with known values. */
static void test_ouster_frame(void **state)
{
    const int32_t shift[3] = {0, 2, -1};
    float in[15], out[15], ranges[15], points[45];
    uint8_t hits[15];
    uint32_t u, v;
    (void)state;
    assert_true(rcu_ouster_in_window(0, 0, 4) && rcu_ouster_in_window(4, 0, 4));
    assert_true(rcu_ouster_in_window(2, 1, 3) && !rcu_ouster_in_window(0, 1, 3) && !rcu_ouster_in_window(4, 1, 3));
    /* [3, 1] wraps: 3, 4, 0, 1 */
    assert_true(rcu_ouster_in_window(3, 3, 1) && rcu_ouster_in_window(4, 3, 1) && rcu_ouster_in_window(0, 3, 1));
    assert_true(rcu_ouster_in_window(1, 3, 1) && !rcu_ouster_in_window(2, 3, 1));
    for (u = 0; u < 15; ++u) {
        in[u] = (float)(10 * (u / 5) + u % 5); /* row * 10 + column */
        ranges[u] = 1.0f;
        hits[u] = 1;
        points[3 * u] = points[3 * u + 1] = points[3 * u + 2] = 2.0f;
    }
    assert_int_equal(rcu_ouster_mask_window(3, 5, 3, 1, hits, ranges, points), 3);
    for (u = 0; u < 3; ++u)
        for (v = 0; v < 5; ++v) {
            const uint32_t k = u * 5 + v;
            if (v == 2) {
                assert_int_equal(hits[k], 0);
                assert_true(isnan(ranges[k]) && isnan(points[3 * k]) && isnan(points[3 * k + 2]));
            } else {
                assert_int_equal(hits[k], 1);
                assert_true(ranges[k] == 1.0f && points[3 * k + 1] == 2.0f);
            }
        }
    assert_int_equal(rcu_ouster_mask_window(3, 5, 0, 4, NULL, ranges, NULL), 0);
    /* out[u][(v + shift[u]) mod 5] = in[u][v] */
    rcu_ouster_destagger(in, out, 3, 5, shift);
    for (u = 0; u < 3; ++u)
        for (v = 0; v < 5; ++v) assert_true(out[u * 5 + (uint32_t)((v + 5 + shift[u]) % 5)] == in[u * 5 + v]);
    assert_true(out[5 + 2] == 10.0f && out[10 + 4] == 20.0f && out[0] == 0.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pose_file_round_trip),
        cmocka_unit_test(test_pose_file_errors),
        cmocka_unit_test(test_pose_file_tum),
        cmocka_unit_test(test_standard_poses_pinned),
        cmocka_unit_test(test_cloud_keeps_returns_and_fields),
        cmocka_unit_test(test_cloud_map_frame),
        cmocka_unit_test(test_cloud_files),
        cmocka_unit_test(test_cloud_stream),
        cmocka_unit_test(test_scan_names),
        cmocka_unit_test(test_ouster_frame),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
