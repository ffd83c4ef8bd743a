/* test_crc32.c - crc32.c against CRC-32 values Python's zlib.crc32 gave
 * for the same bytes (an independent implementation), at every alignment
 * and split, so the slicing-by-8 path and the byte path agree. */
#include <stdint.h>
#include <string.h>

#include "crc32.h"
#include "harness.h"

#define N 100003

/* The bytes the expected values were computed from (the same generator in
 * Python: x = (x * 1103515245 + 12345) mod 2^32, byte = (x >> 16) & 0xff). */
static void fill(uint8_t *b)
{
    uint32_t x = 12345;
    for (size_t i = 0; i < N; i++) {
        x = x * 1103515245u + 12345u;
        b[i] = (uint8_t)(x >> 16);
    }
}

TEST(check_value_of_the_standard)
{
    CHECK(vxl_crc32(0, "123456789", 9) == 0xcbf43926u);
    CHECK(vxl_crc32(0, "", 0) == 0u);
}

TEST(matches_zlib_on_a_long_buffer)
{
    static uint8_t b[N];
    fill(b);
    CHECK(vxl_crc32(0, b, N) == 0xd46efa44u);
    CHECK(vxl_crc32(0, b + 3, 77777) == 0xa6a45e5bu); /* unaligned start, odd length */
}

TEST(any_split_gives_the_same_value)
{
    static uint8_t b[N];
    fill(b);
    const size_t splits[] = {0, 1, 7, 8, 9, 4096, 50001, N - 1, N};
    for (size_t i = 0; i < sizeof splits / sizeof splits[0]; i++) {
        const size_t k = splits[i];
        CHECKF(vxl_crc32(vxl_crc32(0, b, k), b + k, N - k) == 0xd46efa44u, "split at %zu", k);
    }
}

int main(void)
{
    RUN(check_value_of_the_standard);
    RUN(matches_zlib_on_a_long_buffer);
    RUN(any_split_gives_the_same_value);
    return TEST_SUMMARY();
}
