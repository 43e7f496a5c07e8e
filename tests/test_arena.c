/* The arena allocator: costs add up exactly, blocks coalesce, shrink gives the
 * tail back, exhaustion returns NULL. */
#include <string.h>

#include "core/arena.h"
#include "rc_test.h"

static unsigned char raw_block[4096 + 16];
#define block (raw_block + (16u - (uintptr_t)raw_block % 16u) % 16u)
#define BLOCK_SIZE 4096u

static void test_cost_is_header_plus_rounded(void **state)
{
    (void)state;
    assert_int_equal(rc__arena_cost(1), 32);
    assert_int_equal(rc__arena_cost(16), 32);
    assert_int_equal(rc__arena_cost(17), 48);
    assert_int_equal(rc__arena_cost(0), 32);
}

static void test_exact_fill_and_one_more_fails(void **state)
{
    rc__arena a;
    void *p[4];
    int i;
    (void)state;
    rc__arena_init(&a, block, 4 * rc__arena_cost(100));
    for (i = 0; i < 4; ++i) {
        p[i] = rc__arena_alloc(&a, 100);
        assert_non_null(p[i]);
        assert_int_equal((uintptr_t)p[i] % 16, 0);
        memset(p[i], i, 100);
    }
    assert_null(rc__arena_alloc(&a, 1));
    assert_int_equal(a.used, a.size);
    rc__arena_free(&a, p[1]);
    rc__arena_free(&a, p[2]);
    /* the two middle blocks coalesce: room for one 200-byte allocation */
    assert_true(rc__arena_largest_free(&a) >= 200);
    assert_non_null(rc__arena_alloc(&a, 200));
    assert_int_equal(((unsigned char *)p[0])[99], 0);
    assert_int_equal(((unsigned char *)p[3])[0], 3);
    rc__arena_fini(&a);
}

static void test_shrink_and_peak(void **state)
{
    rc__arena a;
    void *p, *q;
    (void)state;
    rc__arena_init(&a, block, BLOCK_SIZE);
    p = rc__arena_alloc(&a, 2000);
    assert_non_null(p);
    assert_int_equal(a.used, rc__arena_cost(2000));
    rc__arena_shrink(&a, p, 100);
    assert_int_equal(a.used, rc__arena_cost(100));
    assert_int_equal(a.peak, rc__arena_cost(2000));
    q = rc__arena_alloc(&a, 1500); /* fits in the freed tail */
    assert_non_null(q);
    assert_true((unsigned char *)q < (unsigned char *)p + 2000);
    rc__arena_free(&a, q);
    rc__arena_free(&a, p);
    assert_int_equal(a.used, 0);
    assert_int_equal(rc__arena_largest_free(&a), BLOCK_SIZE - 16);
    rc__arena_fini(&a);
}

static void test_tiny_arena(void **state)
{
    rc__arena a;
    (void)state;
    rc__arena_init(&a, block, 20); /* rounds down to 16: no usable block */
    assert_null(rc__arena_alloc(&a, 1));
    rc__arena_fini(&a);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cost_is_header_plus_rounded),
        cmocka_unit_test(test_exact_fill_and_one_more_fails),
        cmocka_unit_test(test_shrink_and_peak),
        cmocka_unit_test(test_tiny_arena),
    };
    return cmocka_run_group_tests_name("arena", tests, NULL, NULL);
}
