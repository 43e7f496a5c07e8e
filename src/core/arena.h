/* The arena: a first-fit allocator with coalescing inside one block of memory
 * (the caller's, or one malloc at context creation). Every allocation costs
 * rc__arena_cost(size) bytes: a 16-byte header plus the size rounded up to 16,
 * so size queries can add costs up exactly. Allocations are 16-byte aligned. */
#ifndef RC_CORE_ARENA_H
#define RC_CORE_ARENA_H

#include <stddef.h>
#include <stdint.h>

#define RC__ARENA_ALIGN 16u
#define RC__ARENA_HEADER 16u

typedef struct rc__arena {
    unsigned char *base;   /* 16-aligned */
    size_t size;           /* multiple of 16 */
    size_t used;           /* bytes in allocated blocks, headers included */
    size_t peak;           /* high-water mark of used */
    void *free_list;       /* first free block, address order */
} rc__arena;

/* Bytes one allocation of size bytes takes from the arena. */
size_t rc__arena_cost(size_t size);

/* Sets the arena up over [memory, memory + size): size is rounded down to 16.
 * memory must be 16-aligned. */
void rc__arena_init(rc__arena *arena, void *memory, size_t size);

/* NULL when no free block is large enough. size 0 is treated as 1. */
void *rc__arena_alloc(rc__arena *arena, size_t size);
/* Returns zeroed memory. */
void *rc__arena_calloc(rc__arena *arena, size_t size);
/* ptr NULL is a no-op. */
void rc__arena_free(rc__arena *arena, void *ptr);
/* Gives the tail of an allocation back (new_size <= its size). The block keeps
 * its address. */
void rc__arena_shrink(rc__arena *arena, void *ptr, size_t new_size);
/* Hands the whole block back to the caller (un-poisons it under ASan). */
void rc__arena_fini(rc__arena *arena);
/* Largest single allocation that would succeed now. */
size_t rc__arena_largest_free(const rc__arena *arena);

#endif
