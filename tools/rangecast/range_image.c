#include "range_image.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rangecast/rangecast.h"
#include "util.h"

#if defined(RANGECAST_WITH_PNG)
#include <png.h>
#endif

int rcp_range_image_has_png(void)
{
#if defined(RANGECAST_WITH_PNG)
    return 1;
#else
    return 0;
#endif
}

/* Turbo colour map, polynomial fit (Mikhailov, Google 2019). */
static void turbo(double x, unsigned char rgb[3])
{
    double r, g, b;
    if (x < 0.0) x = 0.0;
    if (x > 1.0) x = 1.0;
    r = 0.13572138 + x * (4.61539260 + x * (-42.66032258 + x * (132.13108234 + x * (-152.94239396 + x * 59.28637943))));
    g = 0.09140261 + x * (2.19418839 + x * (4.84296658 + x * (-14.18503333 + x * (4.27729857 + x * 2.82956604))));
    b = 0.10667330 + x * (12.64194608 + x * (-60.58204836 + x * (110.36276771 + x * (-89.90310912 + x * 27.34824973))));
    rgb[0] = (unsigned char)(255.0 * (r < 0 ? 0 : r > 1 ? 1 : r) + 0.5);
    rgb[1] = (unsigned char)(255.0 * (g < 0 ? 0 : g > 1 ? 1 : g) + 0.5);
    rgb[2] = (unsigned char)(255.0 * (b < 0 ? 0 : b > 1 ? 1 : b) + 0.5);
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* The 1st and 99th percentile of the finite values (0, 1 when none). */
static void auto_scale(const float *v, size_t n, float *lo, float *hi)
{
    float *f = (float *)malloc(n * sizeof(float));
    size_t i, m = 0;
    *lo = 0.0f;
    *hi = 1.0f;
    if (!f) return;
    for (i = 0; i < n; i++)
        if (isfinite(v[i])) f[m++] = v[i];
    if (m > 0) {
        qsort(f, m, sizeof(float), cmp_float);
        *lo = f[(m - 1) / 100];
        *hi = f[(m - 1) - (m - 1) / 100];
        if (!(*hi > *lo)) *hi = *lo + 1.0f;
    }
    free(f);
}

#if !defined(RANGECAST_WITH_PNG)
static void replace_extension(const char *path, const char *ext, char *out, size_t size)
{
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    size_t stem = (dot && (!slash || dot > slash)) ? (size_t)(dot - path) : strlen(path);
    snprintf(out, size, "%.*s.%s", (int)stem, path, ext);
}
#endif

/* Colour of one value (RCP_IMAGE_COLOR). */
static void color_of(float v, float lo, float hi, unsigned char rgb[3])
{
    if (v == INFINITY || v != v) rgb[0] = rgb[1] = rgb[2] = 0;
    else if (v == -INFINITY) rgb[0] = rgb[1] = rgb[2] = 255;
    else turbo(((double)v - lo) / ((double)hi - lo), rgb);
}

/* Writes w x h pixels (RGB8, or native-order uint16 grey) as PNG, or PPM/PGM. */
static int write_pixels(const char *path, unsigned char *pix, uint32_t w, uint32_t h, int gray,
                        char *written, size_t written_size)
{
    char out_path[4096];
    int st = 0;
#if defined(RANGECAST_WITH_PNG)
    png_image img;
    snprintf(out_path, sizeof out_path, "%s", path);
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    img.width = w;
    img.height = h;
    img.format = gray ? PNG_FORMAT_LINEAR_Y : PNG_FORMAT_RGB;
    if (!png_image_write_to_file(&img, out_path, 0, pix, 0, NULL))
        st = rcu_fail("%s: cannot write PNG: %s", out_path, img.message);
#else
    FILE *f;
    size_t i, n = (size_t)w * h;
    replace_extension(path, gray ? "pgm" : "ppm", out_path, sizeof out_path);
    f = fopen(out_path, "wb");
    if (!f) return rcu_fail("%s: %s", out_path, strerror(errno));
    fprintf(f, "%s\n%u %u\n%u\n", gray ? "P5" : "P6", w, h, gray ? 65535u : 255u);
    if (gray) /* PGM 16-bit samples are big-endian */
        for (i = 0; i < n; i++) {
            uint16_t g;
            memcpy(&g, pix + 2 * i, 2);
            pix[2 * i] = (unsigned char)(g >> 8);
            pix[2 * i + 1] = (unsigned char)g;
        }
    if (fwrite(pix, gray ? 2 : 3, n, f) != n) st = -1;
    if (fclose(f) != 0) st = -1;
    if (st != 0) {
        rcu_remove_partial(out_path); /* libpng's writer does the same */
        rcu_fail("%s: write error", out_path);
    }
#endif
    if (st == 0 && written) snprintf(written, written_size, "%s", out_path);
    return st;
}

int rcp_range_image_write(const char *path, const float *values, uint32_t rows, uint32_t columns,
                          const rcp_image_options *o, char *written, size_t written_size)
{
    uint32_t rs = o->row_scale ? o->row_scale : 1, cs = o->col_scale ? o->col_scale : 1;
    uint32_t w = columns * cs, h = rows * rs, x, y;
    int gray = o->mode == RCP_IMAGE_GRAY16;
    size_t px = gray ? 2 : 3;
    unsigned char *pix;
    float lo = o->lo, hi = o->hi;
    int st;

    if (rows == 0 || columns == 0) return rcu_fail("%s: empty image", path);
    if (!gray && lo == hi) auto_scale(values, (size_t)rows * columns, &lo, &hi);
    pix = (unsigned char *)malloc((size_t)w * h * px);
    if (!pix) return rcu_fail("%s: out of memory for a %ux%u image", path, w, h);
    for (y = 0; y < h; y++) {
        uint32_t row = y / rs;
        if (o->flip_rows) row = rows - 1 - row;
        for (x = 0; x < w; x++) {
            float v = values[(size_t)row * columns + x / cs];
            unsigned char *at = pix + ((size_t)y * w + x) * px;
            if (gray) {
                uint16_t g;
                if (v == INFINITY || v != v) g = 0;
                else if (v == -INFINITY) g = 65535;
                else {
                    double mm = (double)v * 1000.0 + 0.5;
                    g = (uint16_t)(mm > 65534.0 ? 65534.0 : mm < 1.0 ? 1.0 : mm);
                }
                memcpy(at, &g, 2); /* native order: what both writers expect */
            } else {
                color_of(v, lo, hi, at);
            }
        }
    }
    st = write_pixels(path, pix, w, h, gray, written, written_size);
    free(pix);
    return st;
}

void rcp_image_options_for(uint32_t model, uint32_t rows, uint32_t columns, rcp_image_options *o)
{
    uint32_t width;
    memset(o, 0, sizeof *o);
    o->mode = RCP_IMAGE_COLOR;
    o->col_scale = columns < 720 ? (720 + columns - 1) / columns : 1;
    width = columns * o->col_scale;
    /* aim at an aspect of about 7:1 at most, e.g. 900 x 16 rows -> 900 x 128 */
    o->row_scale = rows * 7 < width ? (uint32_t)((double)width / rows / 7.0 + 0.5) : 1;
    if (o->row_scale == 0) o->row_scale = 1;
    o->flip_rows = model == RC_SENSOR_SPHERICAL;
}

int rcp_scatter_image_write(const char *path, const float *values, const double *dirs, uint32_t count,
                            uint32_t size, const rcp_image_options *o, char *written,
                            size_t written_size)
{
    double umin = INFINITY, umax = -INFINITY, vmin = INFINITY, vmax = -INFINITY, scale;
    uint32_t i, w, h;
    unsigned char *pix;
    float lo = o->lo, hi = o->hi;
    int st;
    if (count == 0) return rcu_fail("%s: empty scan", path);
    for (i = 0; i < count; i++) {
        const double *d = dirs + 3u * (size_t)i;
        double u = -atan2(d[1], d[0]), v = -atan2(d[2], sqrt(d[0] * d[0] + d[1] * d[1]));
        if (u < umin) umin = u;
        if (u > umax) umax = u;
        if (v < vmin) vmin = v;
        if (v > vmax) vmax = v;
    }
    scale = (double)(size - 8) / fmax(fmax(umax - umin, vmax - vmin), 1e-9);
    w = (uint32_t)((umax - umin) * scale) + 8;
    h = (uint32_t)((vmax - vmin) * scale) + 8;
    if (lo == hi) auto_scale(values, count, &lo, &hi);
    pix = (unsigned char *)malloc((size_t)w * h * 3);
    if (!pix) return rcu_fail("%s: out of memory", path);
    memset(pix, 40, (size_t)w * h * 3);
    for (i = 0; i < count; i++) {
        const double *d = dirs + 3u * (size_t)i;
        double u = -atan2(d[1], d[0]), v = -atan2(d[2], sqrt(d[0] * d[0] + d[1] * d[1]));
        int cx = 4 + (int)((u - umin) * scale + 0.5), cy = 4 + (int)((v - vmin) * scale + 0.5), dx, dy;
        unsigned char rgb[3];
        color_of(values[i], lo, hi, rgb);
        for (dy = -1; dy <= 1; dy++)
            for (dx = -1; dx <= 1; dx++) {
                int x = cx + dx, y = cy + dy;
                if (x < 0 || y < 0 || x >= (int)w || y >= (int)h) continue;
                memcpy(pix + ((size_t)y * w + (size_t)x) * 3, rgb, 3);
            }
    }
    st = write_pixels(path, pix, w, h, 0, written, written_size);
    free(pix);
    return st;
}
