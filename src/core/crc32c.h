/* CRC-32C (Castagnoli, reflected polynomial 0x82F63B78): the checksum of
 * baked maps. Plain C, eight bytes a step (slicing-by-8), about 1 GB/s on the
 * development VM, so checking a 1M-triangle map costs tens of milliseconds
 * against a build's hundreds. */
#ifndef RC_CORE_CRC32C_H
#define RC_CORE_CRC32C_H

#include <stddef.h>
#include <stdint.h>

/* CRC-32C of data[0..n), continuing from crc (0 to start a new one):
 * rc__crc32c(rc__crc32c(0, a, n), b, m) is the CRC of a followed by b.
 * "123456789" gives 0xE3069283. */
uint32_t rc__crc32c(uint32_t crc, const void *data, size_t n);

#endif
