/* Range images of one scan (rows x columns) as PNG (with libpng) or, without
 * it, as PPM/PGM files next to the requested name. */
#ifndef RCP_RANGE_IMAGE_H
#define RCP_RANGE_IMAGE_H

#include <stddef.h>
#include <stdint.h>

#define RCP_IMAGE_COLOR  0u /* 8-bit RGB, turbo colour map (near blue, far red), +inf (no return) black, -inf (too near) white */
#define RCP_IMAGE_GRAY16 1u /* 16-bit grey, millimetres (saturating at 65534), +inf 0, -inf 65535 */

typedef struct rcp_image_options {
    uint32_t mode;        /* RCP_IMAGE_* */
    uint32_t row_scale;   /* each scan row becomes this many pixel rows (0 = 1) */
    uint32_t col_scale;   /* each column this many pixel columns (0 = 1) */
    int flip_rows;        /* 1: scan row 0 at the bottom (spherical sensors: row 0 looks down) */
    float lo, hi;         /* colour scale in metres; lo == hi: the 1st..99th percentile of the scan */
} rcp_image_options;

/* Writes values[row * columns + column]. When PNG support is absent the image
 * goes to the same name with .ppm (colour) or .pgm (grey) instead; the path
 * actually written is copied to written (may be NULL). 0 or -1 (rcu_last_error). */
int rcp_range_image_write(const char *path, const float *values, uint32_t rows, uint32_t columns,
                          const rcp_image_options *options, char *written, size_t written_size);

/* Options that show a scan of this shape well: rows stretched so a 16-row
 * LiDAR scan reads as an image (VLP-16 900 x 16 -> 900 x 128), narrow scans
 * widened, spherical scans flipped so up is up. model is RC_SENSOR_*. */
void rcp_image_options_for(uint32_t model, uint32_t rows, uint32_t columns, rcp_image_options *options);

/* For scans without a grid (O1Dn patterns such as the Livox rosette): each
 * ray becomes a dot at its (azimuth, elevation) in an image of about `size`
 * pixels across, coloured as above, on a dark grey background. dirs: 3
 * doubles a ray, sensor frame (x forward). */
int rcp_scatter_image_write(const char *path, const float *values, const double *dirs, uint32_t count,
                            uint32_t size, const rcp_image_options *options, char *written,
                            size_t written_size);

/* 1 when this program writes PNG files. */
int rcp_range_image_has_png(void);

#endif
