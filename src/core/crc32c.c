#include "core/crc32c.h"

#define POLY 0x82F63B78u

/* table[k][b]: the CRC of byte b followed by k zero bytes. Made per call
 * (2,048 entries, a few microseconds) so there is no shared state to
 * initialise across threads. */
static void make_tables(uint32_t table[8][256])
{
    uint32_t b, k;
    for (b = 0; b < 256u; ++b) {
        uint32_t c = b;
        for (k = 0; k < 8u; ++k) c = (c & 1u) ? (c >> 1) ^ POLY : c >> 1;
        table[0][b] = c;
    }
    for (b = 0; b < 256u; ++b)
        for (k = 1; k < 8u; ++k) table[k][b] = (table[k - 1][b] >> 8) ^ table[0][table[k - 1][b] & 0xFFu];
}

uint32_t rc__crc32c(uint32_t crc, const void *data, size_t n)
{
    uint32_t table[8][256];
    const unsigned char *p = (const unsigned char *)data;
    uint32_t c = ~crc;
    make_tables(table);
    while (n >= 8u) {
        /* bytes, not a 64-bit load: the same on either byte order and at any alignment */
        const uint32_t lo = c ^ ((uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24);
        const uint32_t hi = (uint32_t)p[4] | (uint32_t)p[5] << 8 | (uint32_t)p[6] << 16 | (uint32_t)p[7] << 24;
        c = table[7][lo & 0xFFu] ^ table[6][(lo >> 8) & 0xFFu] ^ table[5][(lo >> 16) & 0xFFu] ^ table[4][lo >> 24] ^
            table[3][hi & 0xFFu] ^ table[2][(hi >> 8) & 0xFFu] ^ table[1][(hi >> 16) & 0xFFu] ^ table[0][hi >> 24];
        p += 8;
        n -= 8u;
    }
    while (n--) c = (c >> 8) ^ table[0][(c ^ *p++) & 0xFFu];
    return ~c;
}
