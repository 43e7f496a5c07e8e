/* rcutil: names of per-scan output files. A name pattern holds one %d or
 * %0Nd (N from 1 to 9), as in "scans/scan_%05d.pcd", which the scan's index
 * replaces; no other '%' (so a pattern is never handed to printf). */
#ifndef RCU_SCAN_NAMES_H
#define RCU_SCAN_NAMES_H

#include <stddef.h>
#include <stdint.h>

/* 1 when path is such a pattern, 0 when it holds no '%' (one file for all
 * scans), -1 when it holds '%' otherwise (message in rcu_last_error). */
int rcu_scan_pattern(const char *path);

/* The name of scan index under pattern (rcu_scan_pattern 1) into out; -1
 * when it does not fit in size bytes (message in rcu_last_error). */
int rcu_scan_name(const char *pattern, uint32_t index, char *out, size_t size);

#endif
