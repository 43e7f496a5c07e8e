/* The CPU's last-level cache size, for sizing work to the caches. */
#ifndef RC_CORE_CACHE_SIZE_H
#define RC_CORE_CACHE_SIZE_H

#include <stdint.h>

/* Bytes of the largest cache cpu0 reports (Linux sysfs), 0 where unknown.
 * Reads with open/read, never stdio, so it allocates nothing: a context on
 * the caller's arena may call it. */
uint64_t rc__last_level_cache_bytes(void);

#endif
