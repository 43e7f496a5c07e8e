/* First-fit allocator with address-ordered free list and coalescing. Each block
 * starts with a 16-byte header holding its total size; free blocks keep the
 * next-free pointer in their payload. Deterministic, no system calls.
 * Block addresses are multiples of RC__ARENA_ALIGN by construction (the base is
 * aligned, every size is rounded up), so the casts from byte pointers to block
 * pointers go through void * to tell -Wcast-align (active on armv7) so. */
#include "core/arena.h"

#include <string.h>

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/asan_interface.h>
#define RC__POISON(p, n) ASAN_POISON_MEMORY_REGION((p), (n))
#define RC__UNPOISON(p, n) ASAN_UNPOISON_MEMORY_REGION((p), (n))
#else
#define RC__POISON(p, n) ((void)(p), (void)(n))
#define RC__UNPOISON(p, n) ((void)(p), (void)(n))
#endif

typedef struct block {
    size_t size;         /* whole block, header included, multiple of 16 */
    size_t tag;          /* BLOCK_USED or BLOCK_FREE */
} block;

typedef struct free_block {
    block head;
    struct free_block *next;
} free_block;

#define BLOCK_USED ((size_t)0x55534544u)
#define BLOCK_FREE ((size_t)0x46524545u)
#define MIN_BLOCK (RC__ARENA_HEADER + RC__ARENA_ALIGN)

static size_t round_up(size_t n) { return (n + (RC__ARENA_ALIGN - 1)) & ~(size_t)(RC__ARENA_ALIGN - 1); }

size_t rc__arena_cost(size_t size)
{
    if (size == 0) size = 1;
    if (size > (size_t)-1 - 2 * RC__ARENA_ALIGN) return (size_t)-1;
    return RC__ARENA_HEADER + round_up(size);
}

void rc__arena_init(rc__arena *arena, void *memory, size_t size)
{
    free_block *f;
    memset(arena, 0, sizeof *arena);
    size &= ~(size_t)(RC__ARENA_ALIGN - 1);
    arena->base = (unsigned char *)memory;
    arena->size = size;
    if (size < MIN_BLOCK) return;
    f = (free_block *)memory;
    f->head.size = size;
    f->head.tag = BLOCK_FREE;
    f->next = NULL;
    arena->free_list = f;
    RC__POISON((unsigned char *)memory + sizeof(free_block), size - sizeof(free_block));
}

void *rc__arena_alloc(rc__arena *arena, size_t size)
{
    size_t need = rc__arena_cost(size);
    free_block **link = (free_block **)&arena->free_list;
    while (*link) {
        free_block *f = *link;
        if (f->head.size >= need) {
            size_t rest = f->head.size - need;
            block *b = &f->head;
            if (rest >= MIN_BLOCK) {
                free_block *tail = (free_block *)(void *)((unsigned char *)f + need);
                RC__UNPOISON(tail, sizeof *tail);
                tail->head.size = rest;
                tail->head.tag = BLOCK_FREE;
                tail->next = f->next;
                *link = tail;
                b->size = need;
            } else {
                *link = f->next;
            }
            b->tag = BLOCK_USED;
            arena->used += b->size;
            if (arena->used > arena->peak) arena->peak = arena->used;
            RC__UNPOISON((unsigned char *)b + RC__ARENA_HEADER, b->size - RC__ARENA_HEADER);
            return (unsigned char *)b + RC__ARENA_HEADER;
        }
        link = &f->next;
    }
    return NULL;
}

void *rc__arena_calloc(rc__arena *arena, size_t size)
{
    void *p = rc__arena_alloc(arena, size);
    if (p) memset(p, 0, size);
    return p;
}

/* Inserts a free block in address order and merges it with its neighbours. */
static void insert_free(rc__arena *arena, free_block *nb)
{
    free_block *prev = NULL;
    free_block *cur = (free_block *)arena->free_list;
    while (cur && cur < nb) {
        prev = cur;
        cur = cur->next;
    }
    nb->head.tag = BLOCK_FREE;
    nb->next = cur;
    if (cur && (unsigned char *)nb + nb->head.size == (unsigned char *)cur) {
        nb->head.size += cur->head.size;
        nb->next = cur->next;
    }
    if (prev) {
        prev->next = nb;
        if ((unsigned char *)prev + prev->head.size == (unsigned char *)nb) {
            prev->head.size += nb->head.size;
            prev->next = nb->next;
            nb = prev;
        }
    } else {
        arena->free_list = nb;
    }
    RC__POISON((unsigned char *)nb + sizeof(free_block), nb->head.size - sizeof(free_block));
}

void rc__arena_free(rc__arena *arena, void *ptr)
{
    block *b;
    if (!ptr) return;
    b = (block *)(void *)((unsigned char *)ptr - RC__ARENA_HEADER);
    if (b->tag != BLOCK_USED) return; /* double free: ignore rather than corrupt */
    arena->used -= b->size;
    insert_free(arena, (free_block *)b);
}

void rc__arena_shrink(rc__arena *arena, void *ptr, size_t new_size)
{
    block *b;
    size_t keep;
    if (!ptr) return;
    b = (block *)(void *)((unsigned char *)ptr - RC__ARENA_HEADER);
    if (b->tag != BLOCK_USED) return;
    keep = rc__arena_cost(new_size);
    if (keep >= b->size || b->size - keep < MIN_BLOCK) return;
    {
        free_block *tail = (free_block *)(void *)((unsigned char *)b + keep);
        RC__UNPOISON(tail, sizeof *tail);
        tail->head.size = b->size - keep;
        arena->used -= tail->head.size;
        b->size = keep;
        insert_free(arena, tail);
    }
}

size_t rc__arena_largest_free(const rc__arena *arena)
{
    size_t best = 0;
    const free_block *f;
    for (f = (const free_block *)arena->free_list; f; f = f->next)
        if (f->head.size > best) best = f->head.size;
    return best > RC__ARENA_HEADER ? best - RC__ARENA_HEADER : 0;
}

void rc__arena_fini(rc__arena *arena)
{
    if (arena->base) RC__UNPOISON(arena->base, arena->size);
    memset(arena, 0, sizeof *arena);
}
