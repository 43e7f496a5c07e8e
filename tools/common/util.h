/* rcutil: error text, a monotonic timer, peak memory, little-endian helpers. */
#ifndef RCU_UTIL_H
#define RCU_UTIL_H

#include <stddef.h>
#include <stdint.h>

/* Message of the last failed rcu_* call ("" when none). Static buffer: rcutil
 * reports errors this way and is therefore not thread-safe. */
const char *rcu_last_error(void);
/* Sets that message (printf style); returns -1 so callers can `return rcu_fail(...)`. */
int rcu_fail(const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;

/* Seconds from an arbitrary fixed point (CLOCK_MONOTONIC). */
double rcu_now(void);

/* Peak resident set size of this process in bytes (getrusage; 0 if unknown). */
uint64_t rcu_peak_rss_bytes(void);

/* Little-endian encode/decode, independent of the host's byte order. */
void rcu_store_le32(unsigned char *p, uint32_t v);
uint32_t rcu_load_le32(const unsigned char *p);
void rcu_store_le16(unsigned char *p, uint16_t v);
void rcu_store_f32le(unsigned char *p, float f);
float rcu_load_f32le(const unsigned char *p);

/* Reads a whole file into a malloc'd buffer (plus a terminating NUL byte not
 * counted in *size). */
int rcu_read_file(const char *path, unsigned char **data, size_t *size);
/* Removes what a failed write left at path, if it is a regular file. */
void rcu_remove_partial(const char *path);

/* The file name extension in lower case without the dot ("" when none), into
 * ext (at most ext_size - 1 characters). */
void rcu_path_extension(const char *path, char *ext, size_t ext_size);

#endif
