/* The PLY reader and writer behind `rangecast simulate --map` and
 * `rangecast gen` (tools/common/ply.c): every encoding it claims (ascii,
 * binary little- and big-endian, any scalar and list type, polygons as fans,
 * unknown properties and elements skipped), a round trip through the writer,
 * a clear message for each kind of broken file, and a mutation run: thousands
 * of damaged copies of valid files, each of which must load as a consistent
 * mesh or fail with a message (under ASan+UBSan in CI: no overrun, no leak). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "meshgen.h"
#include "ply.h"
#include "util.h"

/* Each test writes its own file (ctest may run these in parallel with other
 * runners, never with themselves). */
static void write_bytes(const char *path, const void *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, size, f), size);
    assert_int_equal(fclose(f), 0);
}

static void write_text(const char *path, const char *text)
{
    write_bytes(path, text, strlen(text));
}

/* Reading path fails and the message names the file and contains `what`. */
static void expect_fail(const char *path, const char *what)
{
    rcu_mesh m;
    const char *msg;
    memset(&m, 0x5A, sizeof m);
    assert_int_equal(rcu_mesh_read_ply(path, &m), -1);
    /* nothing half-made is handed back */
    assert_null(m.vertices);
    assert_null(m.indices);
    assert_int_equal(m.vertex_count, 0);
    assert_int_equal(m.triangle_count, 0);
    msg = rcu_last_error();
    if (!strstr(msg, path) || !strstr(msg, what)) {
        print_error("message '%s' lacks '%s' or '%s'\n", msg, path, what);
        fail();
    }
}

static void expect_fail_text(const char *path, const char *text, const char *what)
{
    write_text(path, text);
    expect_fail(path, what);
    remove(path);
}

/* A unit square in z = 0 (two triangles) and a vertex on top: the mesh the
 * encoding tests describe, as the reader must return it. */
static const float SQUARE_V[5][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5f, 0.5f, 2.25f}};

static void assert_square(const rcu_mesh *m, uint32_t expect_tris)
{
    uint32_t i, k;
    assert_int_equal(m->vertex_count, 5);
    for (i = 0; i < 5; ++i)
        for (k = 0; k < 3; ++k) assert_true(m->vertices[3 * i + k] == SQUARE_V[i][k]);
    assert_int_equal(m->triangle_count, expect_tris);
    /* the quad 0 1 2 3 as the fan (0 1 2) (0 2 3) */
    assert_int_equal(m->indices[0], 0);
    assert_int_equal(m->indices[1], 1);
    assert_int_equal(m->indices[2], 2);
    assert_int_equal(m->indices[3], 0);
    assert_int_equal(m->indices[4], 2);
    assert_int_equal(m->indices[5], 3);
}

static void test_ascii_polygons_and_extras(void **state)
{
    const char *path = "test_ply_ascii.ply";
    /* CRLF line ends, comments, an unknown property before x, a double z,
     * a quad, a triangle, a degenerate two-vertex face that is dropped, a
     * second list on the face, and an element the reader does not know */
    const char *text = "ply\r\n"
                       "format ascii 1.0\r\n"
                       "comment made by hand\r\n"
                       "element vertex 5\r\n"
                       "property uchar red\r\n"
                       "property float x\r\n"
                       "property float y\r\n"
                       "property double z\r\n"
                       "element face 3\r\n"
                       "property list uchar float texcoord\r\n"
                       "property list uchar uint vertex_indices\r\n"
                       "element edge 1\r\n"
                       "property int vertex1\r\n"
                       "property int vertex2\r\n"
                       "end_header\r\n"
                       "7 0 0 0\r\n"
                       "7 1 0 0\r\n"
                       "7 1 1 0\r\n"
                       "7 0 1 0\r\n"
                       "7 0.5 0.5 2.25\r\n"
                       "0 4 0 1 2 3\r\n"
                       "2 0.5 0.5 3 0 1 4\r\n"
                       "0 2 3 4\r\n"
                       "0 1\r\n";
    rcu_mesh m;
    (void)state;
    write_text(path, text);
    assert_int_equal(rcu_mesh_read_ply(path, &m), 0);
    assert_square(&m, 3);
    assert_int_equal(m.indices[6], 0);
    assert_int_equal(m.indices[7], 1);
    assert_int_equal(m.indices[8], 4);
    rcu_mesh_free(&m);
    remove(path);
}

/* Appends v as `bytes` bytes, little- or big-endian. */
static size_t put_uint(unsigned char *p, uint64_t v, size_t bytes, int big)
{
    size_t i;
    for (i = 0; i < bytes; ++i) p[big ? bytes - 1 - i : i] = (unsigned char)(v >> (8 * i));
    return bytes;
}

static size_t put_f32(unsigned char *p, float f, int big)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    return put_uint(p, u, 4, big);
}

static size_t put_f64(unsigned char *p, double d, int big)
{
    uint64_t u;
    memcpy(&u, &d, 8);
    return put_uint(p, u, 8, big);
}

/* The square in binary: x float, y double, z float, then a ushort; faces as
 * list uchar ushort (a quad) and list int int (a triangle). */
static size_t binary_square(unsigned char *buf, int big)
{
    size_t n;
    uint32_t i;
    n = (size_t)sprintf((char *)buf,
                        "ply\nformat %s 1.0\nelement vertex 5\nproperty float x\nproperty double y\n"
                        "property float z\nproperty ushort flags\nelement face 2\n"
                        "property list uchar ushort vertex_indices\nend_header\n",
                        big ? "binary_big_endian" : "binary_little_endian");
    for (i = 0; i < 5; ++i) {
        n += put_f32(buf + n, SQUARE_V[i][0], big);
        n += put_f64(buf + n, SQUARE_V[i][1], big);
        n += put_f32(buf + n, SQUARE_V[i][2], big);
        n += put_uint(buf + n, 0xBEEF, 2, big);
    }
    buf[n++] = 4;
    for (i = 0; i < 4; ++i) n += put_uint(buf + n, i, 2, big);
    buf[n++] = 3;
    n += put_uint(buf + n, 0, 2, big);
    n += put_uint(buf + n, 1, 2, big);
    n += put_uint(buf + n, 4, 2, big);
    return n;
}

static void test_binary_both_endians(void **state)
{
    const char *path = "test_ply_binary.ply";
    unsigned char buf[1024];
    int big;
    (void)state;
    for (big = 0; big <= 1; ++big) {
        rcu_mesh m;
        write_bytes(path, buf, binary_square(buf, big));
        assert_int_equal(rcu_mesh_read_ply(path, &m), 0);
        assert_square(&m, 3);
        assert_int_equal(m.indices[8], 4);
        rcu_mesh_free(&m);
    }
    remove(path);
}

static void test_writer_round_trip(void **state)
{
    const char *path = "test_ply_round.ply";
    rcu_mesh a, b;
    (void)state;
    assert_int_equal(rcu_mesh_uv_sphere(3.5f, 17, 9, &a), 0);
    assert_int_equal(rcu_mesh_write_ply(path, &a), 0);
    assert_int_equal(rcu_mesh_read_ply(path, &b), 0);
    assert_int_equal(b.vertex_count, a.vertex_count);
    assert_int_equal(b.triangle_count, a.triangle_count);
    assert_memory_equal(b.vertices, a.vertices, (size_t)a.vertex_count * 3u * sizeof(float));
    assert_memory_equal(b.indices, a.indices, (size_t)a.triangle_count * 3u * sizeof(uint32_t));
    rcu_mesh_free(&a);
    rcu_mesh_free(&b);
    remove(path);
    /* an unwritable path is a message, not a crash */
    assert_int_equal(rcu_mesh_uv_sphere(1.0f, 4, 3, &a), 0);
    assert_int_equal(rcu_mesh_write_ply("no_such_dir/x.ply", &a), -1);
    assert_non_null(strstr(rcu_last_error(), "no_such_dir/x.ply"));
    rcu_mesh_free(&a);
}

#define HEAD "ply\nformat ascii 1.0\n"
#define TRI_BODY "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n" \
                 "element face 1\nproperty list uchar int vertex_indices\nend_header\n"     \
                 "0 0 0\n1 0 0\n0 1 0\n"

static void test_broken_files(void **state)
{
    const char *path = "test_ply_broken.ply";
    (void)state;
    expect_fail("no_such_file.ply", "no_such_file.ply");
    expect_fail_text(path, "", "no 'ply' magic");
    expect_fail_text(path, "solid cube\n", "no 'ply' magic");
    expect_fail_text(path, "ply\nformat ascii 1.0\nelement vertex 3\n", "no end_header");
    expect_fail_text(path, "ply\nformat binary_middle_endian 1.0\nend_header\n", "unknown PLY format");
    expect_fail_text(path, "ply\nelement vertex 0\nend_header\n", "no format line");
    expect_fail_text(path, HEAD "property float x\nend_header\n", "property before any element");
    expect_fail_text(path, HEAD "element vertex 3\nproperty quad x\nend_header\n", "unknown type");
    expect_fail_text(path, HEAD "element vertex 3\nproperty list uchar\nend_header\n", "bad list property");
    expect_fail_text(path, HEAD "element vertex -3\nend_header\n", "bad element count");
    expect_fail_text(path, HEAD "element vertex 3x\nend_header\n", "bad element count");
    expect_fail_text(path, HEAD "elephant 3\nend_header\n", "unexpected PLY header line");
    expect_fail_text(path, HEAD "element vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n",
                     "lacks x, y or z");
    expect_fail_text(path,
                     HEAD "element face 1\nproperty list uchar int vertex_indices\nelement vertex 3\n"
                          "property float x\nproperty float y\nproperty float z\nend_header\n3 0 1 2\n"
                          "0 0 0\n1 0 0\n0 1 0\n",
                     "face element before the vertex element");
    expect_fail_text(path, HEAD TRI_BODY "3 0 1 3\n", "vertex index 3, but there are 3 vertices");
    expect_fail_text(path, HEAD TRI_BODY "3 0 -1 2\n", "vertex index -1");
    expect_fail_text(path, HEAD TRI_BODY "3 0 1.5 2\n", "vertex index");
    expect_fail_text(path, HEAD TRI_BODY "-3 0 1 2\n", "bad list length");
    expect_fail_text(path, HEAD TRI_BODY "3 0 1\n", "ascii data ends early");
    expect_fail_text(path, HEAD TRI_BODY "3 0 one 2\n", "bad number");
    expect_fail_text(path, HEAD TRI_BODY "2 0 1\n", "no triangles");
    expect_fail_text(path, HEAD "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                                "end_header\n0 0 0\n1 0 0\n0 1 0\n",
                     "no triangles");
    expect_fail_text(path, HEAD "element edge 0\nproperty int vertex1\nend_header\n", "no vertex element");
    /* an element without properties holds nothing, however many it claims */
    expect_fail_text(path, HEAD "element nothing 18446744073709551615\nend_header\n", "no vertex element");
    expect_fail_text(path, HEAD "element vertex 18446744073709551616\nend_header\n", "bad element count");
    /* a count the file cannot hold is refused before anything is allocated */
    expect_fail_text(path,
                     "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
                     "property float y\nproperty float z\nend_header\n\1\2\3",
                     "claims 4000000000 entries");
    expect_fail_text(path,
                     "ply\nformat binary_little_endian 1.0\nelement vertex 18446744073709551615\n"
                     "property float x\nproperty float y\nproperty float z\nend_header\n",
                     "claims");
    /* a second vertex element would replace the first under the faces that
     * index it */
    expect_fail_text(path, HEAD "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                                "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                                "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                "0 0 0\n1 0 0\n0 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                     "more than one vertex element");
}

static void test_truncated_binary(void **state)
{
    const char *path = "test_ply_trunc.ply";
    unsigned char buf[1024];
    size_t n, header, cut;
    (void)state;
    n = binary_square(buf, 0);
    header = (size_t)(strstr((const char *)buf, "end_header\n") - (const char *)buf) + 11u;
    /* every cut inside the data: a clear message, never a partial mesh */
    for (cut = header; cut < n; ++cut) {
        write_bytes(path, buf, cut);
        expect_fail(path, cut == header ? "claims" : "");
    }
    remove(path);
}

/* xorshift64*: the mutation run is the same on every platform. */
static uint64_t next_random(uint64_t *s)
{
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return *s * 2685821657736338717ull;
}

/* One damaged copy of src: a few bytes overwritten (random, digits or
 * separators, which ascii headers and counts are made of), a byte dropped or
 * doubled, or the tail cut. */
static size_t mutate(const unsigned char *src, size_t n, unsigned char *dst, uint64_t *s)
{
    static const char useful[] = "0123456789-. \n9e+";
    size_t m = n, k, edits = 1 + next_random(s) % 4;
    memcpy(dst, src, n);
    for (k = 0; k < edits && m > 0; ++k) {
        size_t at = (size_t)(next_random(s) % m);
        switch (next_random(s) % 5) {
        case 0: dst[at] = (unsigned char)next_random(s); break;
        case 1: dst[at] = (unsigned char)useful[next_random(s) % (sizeof useful - 1)]; break;
        case 2: memmove(dst + at, dst + at + 1, m - at - 1), --m; break;
        case 3: memmove(dst + at + 1, dst + at, m - at), ++m; break;
        default: m = at; break;
        }
    }
    return m;
}

static void test_mutations_load_or_fail_cleanly(void **state)
{
    const char *path = "test_ply_mutant.ply";
    unsigned char bin[1024], text[1024], dst[1100];
    const unsigned char *src[2];
    size_t size[2];
    uint64_t seed = 0x9E3779B97F4A7C15ull;
    int i, loaded = 0, failed = 0;
    (void)state;
    size[0] = binary_square(bin, 0);
    size[1] = (size_t)sprintf((char *)text, HEAD TRI_BODY "3 0 1 2\n");
    src[0] = bin;
    src[1] = text;
    for (i = 0; i < 4000; ++i) {
        rcu_mesh m;
        size_t n = mutate(src[i & 1], size[i & 1], dst, &seed);
        write_bytes(path, dst, n);
        if (rcu_mesh_read_ply(path, &m) == 0) {
            uint64_t k;
            /* what loads is a mesh the library can take: indices in range */
            assert_true(m.vertex_count > 0 && m.triangle_count > 0);
            for (k = 0; k < 3u * (uint64_t)m.triangle_count; ++k) assert_true(m.indices[k] < m.vertex_count);
            rcu_mesh_free(&m);
            ++loaded;
        } else {
            assert_null(m.vertices);
            assert_null(m.indices);
            assert_true(strlen(rcu_last_error()) > strlen(path));
            ++failed;
        }
    }
    remove(path);
    /* the run exercised both outcomes */
    assert_true(loaded > 100);
    assert_true(failed > 100);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ascii_polygons_and_extras),
        cmocka_unit_test(test_binary_both_endians),
        cmocka_unit_test(test_writer_round_trip),
        cmocka_unit_test(test_broken_files),
        cmocka_unit_test(test_truncated_binary),
        cmocka_unit_test(test_mutations_load_or_fail_cleanly),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
