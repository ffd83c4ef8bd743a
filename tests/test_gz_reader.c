/* test_gz_reader.c - gz_reader.c, the reader of .nii.gz and plain files,
 * on both OSes (built for Windows too, where it opens zlib1.dll beside the
 * program and a folder named José through wide-character calls). The gzip
 * files are framed here around zlib's own deflate output (compress2, then
 * the zlib wrapper swapped for gzip's header and CRC-32 trailer), so the
 * test needs nothing the library does not load itself. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "crc32.h"
#include "files.h"
#include "gz_reader.h"
#include "harness.h"
#include "utf8_temp.h"
#include "zlib_api.h"

#define N 200000

static unsigned char data[N];

/* Compressible but not trivial: runs of a slowly changing byte plus noise. */
static void fill_data(void)
{
    uint32_t x = 7;
    for (size_t i = 0; i < N; i++) {
        x = x * 1103515245u + 12345u;
        data[i] = (unsigned char)((i / 97) * 13 + ((x >> 16) & 3));
    }
}

static void put_le32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++) p[i] = (unsigned char)(v >> (8 * i));
}

/* One gzip member of src[0..n) appended to out at *len; 0 or -1. */
static int gzip_member(const unsigned char *src, size_t n, unsigned char *out, size_t cap, size_t *len)
{
    vxl_err e = {0};
    const vxl_zlib *z = vxl_zlib_api(&e);
    if (!z) return -1;
    uLongf zn = z->compressBound((uLong)n);
    unsigned char *zbuf = malloc(zn);
    if (!zbuf || z->compress2(zbuf, &zn, src, (uLong)n, 6) != Z_OK || zn < 6) {
        free(zbuf);
        return -1;
    }
    /* zlib's 2-byte header and 4-byte Adler-32 go; gzip's 10-byte header and
     * its CRC-32 and length trailer come instead */
    const size_t body = zn - 6;
    if (*len + 10 + body + 8 > cap) {
        free(zbuf);
        return -1;
    }
    static const unsigned char header[10] = {0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 0, 0xff};
    memcpy(out + *len, header, 10);
    memcpy(out + *len + 10, zbuf + 2, body);
    put_le32(out + *len + 10 + body, vxl_crc32(0, src, n));
    put_le32(out + *len + 14 + body, (uint32_t)n);
    *len += 10 + body + 8;
    free(zbuf);
    return 0;
}

static char folder[4096];

static const char *path_of(const char *name, char *out, size_t n)
{
    snprintf(out, n, "%s/%s", folder, name);
    return out;
}

static int write_file(const char *path, const void *p, size_t n)
{
    FILE *f = vxl_fopen(path, "wb");
    if (!f) return -1;
    int ok = fwrite(p, 1, n, f) == n;
    return fclose(f) == 0 && ok ? 0 : -1;
}

/* The whole stream of path, read in steps of `step` bytes, equals want[0..n). */
static int reads_back(const char *path, size_t buffer, size_t step, const unsigned char *want, size_t n)
{
    vxl_err e = {0};
    vxl_gz *f = vxl_gz_open(path, buffer, &e);
    if (!f) return 0;
    unsigned char *got = malloc(n + 16);
    size_t have = 0;
    int ok = got != NULL;
    while (ok) {
        size_t s = 0, room = n + 16 - have;
        if (vxl_gz_read(f, got + have, step < room ? step : room, &s, &e) != VXL_OK) ok = 0;
        if (s == 0) break;
        have += s;
    }
    ok = ok && have == n && memcmp(got, want, n) == 0;
    if (!ok) fprintf(stderr, "%s: %zu of %zu bytes read: %s\n", path, have, n, e.msg);
    free(got);
    vxl_gz_close(f);
    return ok;
}

/* path opens, as a plain file (direct 1) or as gzip (0). */
static int opens_as(const char *path, int direct)
{
    vxl_err e = {0};
    vxl_gz *f = vxl_gz_open(path, 0, &e);
    const int ok = f && vxl_gz_direct(f) == direct;
    vxl_gz_close(f);
    return ok;
}

static unsigned char gz[2 * N + 1024];
static size_t gz_len;

/* gz: one member of all of data; written to the folder as name (path in p). */
static int gzip_file(const char *name, char *p, size_t n)
{
    gz_len = 0;
    return gzip_member(data, N, gz, sizeof gz, &gz_len) || write_file(path_of(name, p, n), gz, gz_len) ? -1 : 0;
}

TEST(plain_file_reads_as_it_is)
{
    char p[4200];
    REQUIRE(write_file(path_of("plain.nii", p, sizeof p), data, N) == 0);
    CHECK(opens_as(p, 1));
    CHECK(reads_back(p, 0, 4096, data, N));
    CHECK(reads_back(p, 0, N + 10, data, N));
}

TEST(gzip_reads_whole_at_any_buffer_and_step)
{
    char p[4200];
    REQUIRE(gzip_file("one.nii.gz", p, sizeof p) == 0);
    CHECK(opens_as(p, 0));
    /* buffers from a few bytes (a gzip header spread over several reads of
     * the file: each is a system call, slow under Wine, so not one byte) to
     * more than the file; steps from one byte to more than the stream */
    const size_t buffers[] = {0, 13, 4096, 65536};
    const size_t steps[] = {1, 333, 65536, N, N + 1};
    for (size_t b = 0; b < 4; b++)
        for (size_t s = 0; s < 5; s++) {
            if (steps[s] == 1 && buffers[b] != 4096) continue; /* one-byte steps: once is enough */
            CHECKF(reads_back(p, buffers[b], steps[s], data, N), "buffer %zu step %zu", buffers[b], steps[s]);
        }
}

TEST(concatenated_members_read_as_one_stream_and_trailing_bytes_are_ignored)
{
    char p[4200];
    gz_len = 0;
    REQUIRE(gzip_member(data, N / 2, gz, sizeof gz, &gz_len) == 0);
    REQUIRE(gzip_member(data + N / 2, N - N / 2, gz, sizeof gz, &gz_len) == 0);
    REQUIRE(write_file(path_of("two.nii.gz", p, sizeof p), gz, gz_len) == 0);
    CHECK(reads_back(p, 0, 5000, data, N));
    CHECK(reads_back(p, 13, 5000, data, N)); /* a member boundary inside one read of the file */
    memset(gz + gz_len, 0, 64); /* padding some tools leave after the data */
    REQUIRE(write_file(p, gz, gz_len + 64) == 0);
    CHECK(reads_back(p, 0, 5000, data, N));
}

TEST(seeks_forward_and_back)
{
    char p[4200];
    REQUIRE(gzip_file("seek.nii.gz", p, sizeof p) == 0);
    vxl_err e = {0};
    vxl_gz *f = vxl_gz_open(p, 1000, &e);
    REQUIRE(f != NULL);
    unsigned char b[64];
    size_t got = 0;
    const uint64_t at[] = {352, 150000, 10, 0, N - 8, N + 100};
    for (size_t i = 0; i < sizeof at / sizeof at[0]; i++) {
        CHECK(vxl_gz_seek(f, at[i], &e) == VXL_OK);
        CHECK(vxl_gz_read(f, b, sizeof b, &got, &e) == VXL_OK);
        const size_t want = at[i] >= N ? 0 : N - at[i] < sizeof b ? (size_t)(N - at[i]) : sizeof b;
        CHECKF(got == want && (want == 0 || memcmp(b, data + at[i], want) == 0), "at %llu: %zu bytes",
               (unsigned long long)at[i], got);
    }
    vxl_gz_close(f);
}

/* Reading all of path fails with code and a message holding `says`. */
static int fails_with(const char *path, int code, const char *says)
{
    vxl_err e = {0};
    vxl_gz *f = vxl_gz_open(path, 0, &e);
    int rc = f ? VXL_OK : e.code;
    static unsigned char sink[N];
    size_t got = 0;
    while (f && rc == VXL_OK && (rc = vxl_gz_read(f, sink, sizeof sink, &got, &e)) == VXL_OK && got) {}
    vxl_gz_close(f);
    return rc == code && strstr(e.msg, says) != NULL;
}

TEST(cut_and_corrupt_streams_are_format_errors)
{
    char p[4200];
    gz_len = 0;
    REQUIRE(gzip_member(data, N, gz, sizeof gz, &gz_len) == 0);
    const size_t cuts[] = {3, 10, 11, gz_len / 2, gz_len - 9, gz_len - 1};
    for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; i++) {
        REQUIRE(write_file(path_of("cut.nii.gz", p, sizeof p), gz, cuts[i]) == 0);
        CHECKF(fails_with(p, VXL_ERR_FORMAT, "truncated"), "cut at %zu of %zu", cuts[i], gz_len);
    }
    /* a changed byte in the deflate data: a bad block or the CRC-32 catches it */
    gz[gz_len / 3] ^= 0x55;
    REQUIRE(write_file(path_of("bad.nii.gz", p, sizeof p), gz, gz_len) == 0);
    CHECK(fails_with(p, VXL_ERR_FORMAT, "bad.nii.gz"));
    CHECK(fails_with(path_of("missing.nii.gz", p, sizeof p), VXL_ERR_IO, "missing.nii.gz"));
}

int main(void)
{
    utf8_temp_folder("gz", folder, sizeof folder);
    if (vxl_mkdir(folder) != 0) {
        fprintf(stderr, "cannot make %s\n", folder);
        return 1;
    }
    fill_data();
    RUN(plain_file_reads_as_it_is);
    RUN(gzip_reads_whole_at_any_buffer_and_step);
    RUN(concatenated_members_read_as_one_stream_and_trailing_bytes_are_ignored);
    RUN(seeks_forward_and_back);
    RUN(cut_and_corrupt_streams_are_format_errors);
    return TEST_SUMMARY();
}
