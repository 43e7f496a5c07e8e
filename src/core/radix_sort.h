/* Sorting of (key, value) pairs by key: least significant digit first, eight
 * bits a pass, stable, no allocation (the caller hands in a second pair of
 * arrays to move through). Used to order work, so only its speed matters to
 * the results: any order gives the same bits. */
#ifndef RC_CORE_RADIX_SORT_H
#define RC_CORE_RADIX_SORT_H

#include <stdint.h>

/* Sorts keys[0..n) ascending, moving values[i] with keys[i] (equal keys keep
 * their order). Only the low `bits` bits of the keys are looked at (at most
 * 32). tmp_keys and tmp_values hold n entries each; on return the sorted
 * pairs are in keys and values, and the tmp arrays hold nothing useful. */
void rc__radix_sort_pairs(uint32_t *keys, uint32_t *values, uint32_t *tmp_keys, uint32_t *tmp_values, uint32_t n,
                          uint32_t bits);

/* Bits needed to write v (0 for 0). */
uint32_t rc__bit_width(uint32_t v);

#endif
