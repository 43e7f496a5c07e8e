/* What an Ouster frame does to the rays it measured, after simulation:
 * the column window (columns outside it carry no data) and destaggering (the
 * sensor's measurement-id order, where each beam's row is shifted by its
 * azimuth offset, turned into an image whose columns share one azimuth).
 * Both follow the metadata's lidar_data_format: column_window [start, end]
 * (inclusive, wrapping past the last column when start > end) and
 * pixel_shift_by_row (one shift a beam). */
#ifndef RCU_OUSTER_FRAME_H
#define RCU_OUSTER_FRAME_H

#include <stdint.h>

/* 1 when measurement id column of a frame lies in the window [start, end]. */
int rcu_ouster_in_window(uint32_t column, uint32_t start, uint32_t end);

/* Marks the elements of a scan (rows x columns, ray = row * columns +
 * column) whose column lies outside the window as no data: hit 0, range NaN
 * (REP 117's invalid measurement), point NaN. Any array may be NULL. Returns
 * how many elements it marked. */
uint64_t rcu_ouster_mask_window(uint32_t rows, uint32_t columns, uint32_t start, uint32_t end, uint8_t *hits,
                                float *ranges, float *points);

/* Destaggers one field of a scan, as Ouster's SDK does (client.destagger):
 * out[u][(v + shift[u]) mod columns] = in[u][v]. in and out must not overlap. */
void rcu_ouster_destagger(const float *in, float *out, uint32_t rows, uint32_t columns, const int32_t *shift);

#endif
