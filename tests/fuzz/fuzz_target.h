/* What every fuzz target here defines: the libFuzzer entry point. The same
 * file builds two ways: with clang's -fsanitize=fuzzer (libFuzzer drives it;
 * `make fuzz`), and with replay.c's main (any compiler; ctest runs it over the
 * checked-in corpus, so an input that once broke something stays a test). */
#ifndef RC_FUZZ_TARGET_H
#define RC_FUZZ_TARGET_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* A property the library promises: a breach is a finding, like a crash. */
#define FZ_REQUIRE(cond, what)                                                  \
    do {                                                                        \
        if (!(cond)) {                                                          \
            fprintf(stderr, "fuzz: %s (%s:%d)\n", what, __FILE__, __LINE__);    \
            abort();                                                            \
        }                                                                       \
    } while (0)

/* The input as a file (for readers that take paths): a private file in the
 * temporary directory, rewritten each call, its path in a static buffer.
 * NULL when the file cannot be written. Removed at exit. */
const char *fz_input_file(const uint8_t *data, size_t size, const char *suffix);

#endif
