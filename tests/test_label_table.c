/* test_label_table.c - vxl_label_table_load (csrc/io/label_table.c): each
 * format's ids, names, colours, opacity and visibility; the MRIcron
 * .lut/.txt pair from either side; sorting; max/count; names cut to 63
 * bytes of valid UTF-8; and malformed files (truncated palettes, bad
 * numbers, long lines, huge ids, repeated ids, binary garbage, too many
 * labels) giving clear errors. The fuzz target's crash corpus
 * (tests/crashers/label_table/) is replayed at the end. */
#include <dirent.h>
#include <ftw.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "fuzz/label_table_input.h"
#include "fuzz/label_table_samples.h"
#include "harness.h"
#include "voxlight.h"

static char g_dir[64];

static int remove_entry(const char *p, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)st, (void)flag, (void)ftw;
    return remove(p);
}

static const char *file_path(const char *name)
{
    static char p[256];
    snprintf(p, sizeof p, "%s/%s", g_dir, name);
    return p;
}

static const char *write_bytes(const char *name, const void *data, size_t n)
{
    const char *p = file_path(name);
    FILE *f = fopen(p, "wb");
    if (!f) return p;
    if (n) fwrite(data, 1, n, f);
    fclose(f);
    return p;
}

static const char *write_text(const char *name, const char *text) { return write_bytes(name, text, strlen(text)); }

/* Loads path into t[max]; returns the count, or -1 on failure. */
static int load(const char *path, vxl_label_entry *t, uint32_t max)
{
    uint32_t n = 0;
    if (max) t[0].struct_size = sizeof *t;
    if (vxl_label_table_load(path, t, max, &n) != VXL_OK) return -1;
    return (int)n;
}

static int near(float a, float b) { return fabsf(a - b) < 1e-6f; }

static int rgba_is(const vxl_label_entry *e, int r, int g, int b, float a)
{
    return near(e->color[0], r / 255.0f) && near(e->color[1], g / 255.0f) && near(e->color[2], b / 255.0f) &&
           near(e->color[3], a);
}

/* The load fails with code, and its message names the file and holds want. */
static void expect_error(vxl_test_ctx *T_, const char *path, int code, const char *want)
{
    uint32_t n = 99;
    int rc = vxl_label_table_load(path, NULL, 0, &n);
    const char *msg = vxl_last_error();
    CHECKF(rc == code, "%s: rc %d, want %d (%s)", path, rc, code, msg);
    CHECKF(n == 0, "%s: count %u after a failure", path, n);
    CHECKF(strstr(msg, path) != NULL, "message '%s' does not name %s", msg, path);
    CHECKF(!want || strstr(msg, want) != NULL, "message '%s' lacks '%s'", msg, want);
}

/* ------------------------------------------------------------ formats */

TEST(freesurfer_lut_sorted_with_transparency_as_255_minus_alpha)
{
    vxl_label_entry t[8];
    int n = load(write_text("FreeSurferColorLUT.txt", lt_freesurfer), t, 8);
    REQUIRE(n == 4);
    CHECK(t[0].id == 0 && t[1].id == 2 && t[2].id == 17 && t[3].id == 1000);
    CHECK(!strcmp(t[0].name, "Unknown") && !strcmp(t[1].name, "Left-Cerebral-White-Matter"));
    CHECK(!strcmp(t[2].name, "Left-Hippocampus") && !strcmp(t[3].name, "ctx-lh-unknown"));
    CHECK(rgba_is(&t[2], 220, 216, 20, 1.0f)); /* T 0: opaque */
    CHECK(rgba_is(&t[1], 245, 245, 245, 0.0f)); /* T 255: clear (tissue-type column read past) */
    CHECK(rgba_is(&t[3], 25, 5, 25, 200.0f / 255.0f));
    for (int i = 0; i < n; i++) CHECK(t[i].visible == 1 && t[i].struct_size == sizeof t[0]);
}

TEST(slicer_ctbl_opacity_by_header_or_extension)
{
    vxl_label_entry t[8];
    int n = load(write_text("header_only.txt", lt_slicer), t, 8); /* the header comment decides */
    REQUIRE(n == 4);
    CHECK(t[0].id == 0 && t[1].id == 1 && t[2].id == 2 && t[3].id == 3);
    CHECK(!strcmp(t[3].name, "connective_tissue") && !strcmp(t[2].name, "bone"));
    CHECK(rgba_is(&t[0], 0, 0, 0, 0.0f));
    CHECK(rgba_is(&t[1], 216, 101, 79, 1.0f));
    CHECK(rgba_is(&t[3], 111, 184, 210, 128.0f / 255.0f));
    /* no header: .ctbl is Slicer (A = opacity), .txt is FreeSurfer (A = transparency) */
    REQUIRE(load(write_text("bare.ctbl", lt_slicer_bare), t, 8) == 2);
    CHECK(near(t[0].color[3], 1.0f) && near(t[1].color[3], 0.0f));
    REQUIRE(load(write_text("bare.txt", lt_slicer_bare), t, 8) == 2);
    CHECK(near(t[0].color[3], 0.0f) && near(t[1].color[3], 1.0f));
    expect_error(T_, write_text("procedural.txt", "# Color procedural file /x.txt\n# 2 points\n0 0 0 0\n255 1 1 1\n"),
                 VXL_ERR_FORMAT, "continuous colour map");
}

TEST(itksnap_opacity_visibility_and_quoted_names)
{
    vxl_label_entry t[8];
    int n = load(write_text("labels.label", lt_itksnap), t, 8);
    REQUIRE(n == 3);
    CHECK(t[0].id == 0 && !strcmp(t[0].name, "Clear Label") && t[0].visible == 0 && rgba_is(&t[0], 0, 0, 0, 0.0f));
    CHECK(t[1].id == 1 && !strcmp(t[1].name, "Left ventricle") && t[1].visible == 1);
    CHECK(rgba_is(&t[1], 255, 0, 0, 1.0f));
    CHECK(t[2].id == 12 && !strcmp(t[2].name, "Myocardium wall") && t[2].visible == 0);
    CHECK(rgba_is(&t[2], 0, 255, 0, 0.5f));
    /* no header comment: the quoted name on the first data line tells */
    REQUIRE(load(write_text("bare.txt", "5 1 2 3 0.25 1 0 \"x y\"\n"), t, 8) == 1);
    CHECK(t[0].id == 5 && !strcmp(t[0].name, "x y") && rgba_is(&t[0], 1, 2, 3, 0.25f));
}

/* ------------------------------------------------------------- MRIcron */

TEST(mricron_pair_from_either_side_and_the_palette_alone)
{
    unsigned char pal[768];
    lt_palette(pal);
    vxl_label_entry t[300];
    const char *lut = write_bytes("atlas.nii.lut", pal, sizeof pal);
    /* alone: 256 unnamed entries, entry i = (R[i], G[i], B[i]) */
    REQUIRE(load(lut, t, 300) == 256);
    for (int i = 0; i < 256; i++)
        CHECKF(t[i].id == i && rgba_is(&t[i], i, 255 - i, (7 * i) & 255, 1.0f) && !t[i].name[0] && t[i].visible,
               "entry %d", i);
    /* with the names beside it: their ids, coloured by the palette */
    write_text("atlas.nii.txt", lt_names);
    const char *paths[2] = {lut, file_path("atlas.nii.txt")};
    for (int k = 0; k < 2; k++) {
        int n = load(paths[k], t, 300);
        REQUIRE(n == 3);
        CHECK(t[0].id == 1 && !strcmp(t[0].name, "Precentral_L") && rgba_is(&t[0], 1, 254, 7, 1.0f));
        CHECK(t[1].id == 2 && !strcmp(t[1].name, "Precentral_R") && rgba_is(&t[1], 2, 253, 14, 1.0f));
        CHECK(t[2].id == 7 && !strcmp(t[2].name, "Frontal_Mid_L") && rgba_is(&t[2], 7, 248, 49, 1.0f));
    }
    /* an id past 255 takes palette entry id mod 256 */
    write_text("wrap.txt", "300 Far\n");
    write_bytes("wrap.lut", pal, sizeof pal);
    REQUIRE(load(file_path("wrap.txt"), t, 300) == 1);
    CHECK(rgba_is(&t[0], 44, 211, (7 * 44) & 255, 1.0f));
}

TEST(names_alone_take_the_documented_default_palette)
{
    vxl_label_entry t[4], u[4];
    REQUIRE(load(write_text("names_only.txt", "0 Zero\n1 One\n2 Two\n"), t, 4) == 3);
    REQUIRE(load(file_path("names_only.txt"), u, 4) == 3);
    CHECK(!memcmp(t, u, sizeof t[0] * 3)); /* deterministic */
    /* id 0: hue 0, saturation 0.65, value 0.95 (docs/labels.md) */
    CHECK(near(t[0].color[0], 0.95f) && near(t[0].color[1], 0.3325f) && near(t[0].color[2], 0.3325f));
    /* id 1: hue 0.618 (blue-violet sector 3: r = p, g = q, b = v) */
    double h = 0.6180339887498949 * 6.0 - 3.0;
    CHECK(near(t[1].color[0], 0.3325f) && near(t[1].color[1], (float)(0.95 * (1 - 0.65 * h))) &&
          near(t[1].color[2], 0.95f));
    for (int i = 0; i < 3; i++) CHECK(near(t[i].color[3], 1.0f) && t[i].visible == 1);
    CHECK(!strcmp(t[2].name, "Two"));
}

TEST(real_mricron_jhu_atlas_and_its_long_names)
{
    /* mricron-data (build.sh installs it): the JHU atlas names 49 labels, 0
     * to 48, some longer than 63 bytes; colours from its .lut */
    const char *jhu = "/usr/share/mricron/templates/JHU-WhiteMatter-labels-1mm.nii.lut";
    struct stat st;
    REQUIRE(stat(jhu, &st) == 0);
    vxl_label_entry t[64];
    REQUIRE(load(jhu, t, 64) == 49);
    CHECK(t[0].id == 0 && !strcmp(t[0].name, "Unclassified") && t[48].id == 48);
    CHECK(!strcmp(t[48].name, "Tapetum_L"));
    CHECK(strlen(t[39].name) == 63 && !strncmp(t[39].name, "Fornix_(cres)_/_Stria_terminalis", 32));
}

/* ------------------------------------------------------ API semantics */

TEST(count_without_out_then_max_and_stride)
{
    const char *p = write_text("fs.txt", lt_freesurfer);
    uint32_t n = 0;
    CHECK(vxl_label_table_load(p, NULL, 0, &n) == VXL_OK && n == 4);
    /* max 2: the two lowest ids, count still 4 */
    vxl_label_entry t[4];
    memset(t, 0x55, sizeof t);
    t[0].struct_size = sizeof t[0];
    CHECK(vxl_label_table_load(p, t, 2, &n) == VXL_OK && n == 4);
    CHECK(t[0].id == 0 && t[1].id == 2);
    CHECK(t[2].struct_size == 0x55555555u); /* untouched past max */
    /* a larger stride (a newer caller's struct): entries land at it */
    struct wide {
        vxl_label_entry e;
        char more[40];
    } w[4];
    memset(w, 0, sizeof w);
    w[0].e.struct_size = sizeof w[0];
    CHECK(vxl_label_table_load(p, &w[0].e, 4, &n) == VXL_OK && n == 4);
    CHECK(w[3].e.id == 1000 && !strcmp(w[3].e.name, "ctx-lh-unknown") && w[3].e.struct_size == sizeof(vxl_label_entry));
    /* struct_size 0 means sizeof */
    t[0].struct_size = 0;
    CHECK(vxl_label_table_load(p, t, 4, &n) == VXL_OK && t[3].id == 1000);
    /* bad arguments */
    CHECK(vxl_label_table_load(p, NULL, 0, NULL) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(vxl_label_table_load(p, NULL, 3, &n) == VXL_ERR_INVALID_ARGUMENT);
    CHECK(vxl_label_table_load("", NULL, 0, &n) == VXL_ERR_INVALID_ARGUMENT && n == 0);
    CHECK(vxl_label_table_load(NULL, NULL, 0, &n) == VXL_ERR_INVALID_ARGUMENT);
}

TEST(names_are_cut_to_63_bytes_of_valid_utf8)
{
    char line[256], name[128];
    memset(name, 'a', 62);
    strcpy(name + 62, "\xC3\xA9z"); /* 'é' would end at byte 64: cut before it */
    snprintf(line, sizeof line, "1 %s 1 2 3 0\n", name);
    vxl_label_entry t[2];
    REQUIRE(load(write_text("long.txt", line), t, 2) == 1);
    CHECK(strlen(t[0].name) == 62 && t[0].name[61] == 'a');
    /* 61 ASCII + 'é' fits exactly */
    memset(name, 'b', 61);
    strcpy(name + 61, "\xC3\xA9zz");
    snprintf(line, sizeof line, "1 %s 1 2 3 0\n", name);
    REQUIRE(load(write_text("long2.txt", line), t, 2) == 1);
    CHECK(strlen(t[0].name) == 63 && !strcmp(t[0].name + 61, "\xC3\xA9"));
    /* invalid UTF-8 (Latin-1, a lone continuation, an overlong '/') becomes '?' */
    REQUIRE(load(write_text("latin1.txt", "4 Caf\xE9-\x80-\xC0\xAF 1 2 3 0\n"), t, 2) == 1);
    CHECK(!strcmp(t[0].name, "Caf?-?-??"));
    /* a byte order mark is not part of the first id */
    REQUIRE(load(write_text("bom.txt", "\xEF\xBB\xBF" "9 Nine\n"), t, 2) == 1);
    CHECK(t[0].id == 9 && !strcmp(t[0].name, "Nine"));
}

TEST(int32_ids_and_negative_ids)
{
    vxl_label_entry t[4];
    REQUIRE(load(write_text("ids.txt", "2147483647 Max 1 1 1 0\n-2147483648 Min 2 2 2 0\n0 Zero 3 3 3 0\n"), t, 4) ==
            3);
    CHECK(t[0].id == INT32_MIN && t[1].id == 0 && t[2].id == INT32_MAX);
    expect_error(T_, write_text("huge.txt", "0 Zero 0 0 0 0\n2147483648 Huge 1 2 3 0\n"), VXL_ERR_FORMAT, "line 2");
    expect_error(T_, write_text("huge_neg.txt", "-2147483649 Neg 1 2 3 0\n"), VXL_ERR_FORMAT, "int32");
    expect_error(T_, write_text("long_digits.txt", "99999999999999999999999999 X 1 2 3 0\n"), VXL_ERR_FORMAT, "line 1");
}

/* ------------------------------------------------------------ hostile */

TEST(repeated_ids_are_an_error_naming_both_lines)
{
    expect_error(T_, write_text("dup.txt", "# c\n1 A 1 2 3 0\n2 B 1 2 3 0\n1 C 4 5 6 0\n"), VXL_ERR_FORMAT,
                 "label id 1 on line 4 repeats line 2");
    expect_error(T_, write_text("dup_names.txt", "3 A\n3 B\n"), VXL_ERR_FORMAT, "repeats line 1");
    /* in a pair opened by its .lut, the lines are the .txt's: both files are named */
    unsigned char pal[768];
    lt_palette(pal);
    write_text("dup_pair.txt", "5 A\n6 B\n5 C\n");
    expect_error(T_, write_bytes("dup_pair.lut", pal, sizeof pal), VXL_ERR_FORMAT,
                 "dup_pair.txt': label id 5 on line 3 repeats line 1 (the label names for");
}

TEST(malformed_files_give_clear_errors)
{
    unsigned char pal[768];
    lt_palette(pal);
    /* a palette cut short (binary, not text) */
    expect_error(T_, write_bytes("cut.lut", pal, 700), VXL_ERR_FORMAT, "768");
    /* a .lut of the right size whose .txt is broken: the .txt is named */
    write_bytes("pair.lut", pal, sizeof pal);
    write_text("pair.txt", "1 A\nB 2\n");
    expect_error(T_, file_path("pair.lut"), VXL_ERR_FORMAT, "pair.txt' line 2");
    /* numbers */
    expect_error(T_, write_text("r256.txt", "1 A 256 0 0 0\n"), VXL_ERR_FORMAT, "line 1");
    expect_error(T_, write_text("r_neg.txt", "1 A 1 -2 0 0\n"), VXL_ERR_FORMAT, "0..255");
    expect_error(T_, write_text("alpha.txt", "1 A 1 2 3 300\n"), VXL_ERR_FORMAT, "0..255");
    expect_error(T_, write_text("float_rgb.txt", "1 A 1 2 3 0\n2 B 1.5 2 3 0\n"), VXL_ERR_FORMAT, "line 2");
    expect_error(T_, write_text("cols.txt", "1 A 1 2 3 0 0 0\n"), VXL_ERR_FORMAT, "too many columns");
    expect_error(T_, write_text("short.txt", "1 A 1 2 3 0\n2 B 1 2\n"), VXL_ERR_FORMAT, "line 2");
    expect_error(T_, write_text("id_text.txt", "1 A 1 2 3 0\nx B 1 2 3 0\n"), VXL_ERR_FORMAT, "label id");
    /* ITK-SNAP */
    expect_error(T_, write_text("a.label", "1 1 2 3 1.5 1 1 \"A\"\n"), VXL_ERR_FORMAT, "opacity");
    expect_error(T_, write_text("vis.label", "1 1 2 3 1 2 1 \"A\"\n"), VXL_ERR_FORMAT, "VIS");
    expect_error(T_, write_text("quote.label", "1 1 2 3 1 1 1 \"A\n"), VXL_ERR_FORMAT, "quoted");
    expect_error(T_, write_text("nan.label", "1 1 2 3 nan 1 1 \"A\"\n"), VXL_ERR_FORMAT, "opacity");
    /* an overlong line */
    char *big = malloc(3000);
    REQUIRE(big);
    memset(big, 'x', 2999);
    big[0] = '1', big[1] = ' ', big[2999] = '\0';
    expect_error(T_, write_text("wide.txt", big), VXL_ERR_FORMAT, "longer than 1024 bytes");
    free(big);
    /* not a table at all */
    expect_error(T_, write_text("empty.txt", ""), VXL_ERR_FORMAT, "no labels");
    expect_error(T_, write_text("comments.txt", "# nothing\n\n#more\n"), VXL_ERR_FORMAT, "no labels");
    expect_error(T_, write_text("prose.txt", "hello world\n"), VXL_ERR_FORMAT, "not a label table");
    unsigned char garbage[500];
    for (int i = 0; i < 500; i++) garbage[i] = (unsigned char)(i * 131 + 7);
    expect_error(T_, write_bytes("garbage.bin", garbage, sizeof garbage), VXL_ERR_FORMAT, "neither");
    expect_error(T_, file_path("no_such_file.txt"), VXL_ERR_IO, NULL);
    expect_error(T_, g_dir, VXL_ERR_IO, "not a regular file");
}

TEST(caps_on_entries_and_file_size)
{
    /* 65537 labels: over the cap */
    FILE *f = fopen(file_path("many.txt"), "wb");
    REQUIRE(f);
    for (int i = 0; i <= 65536; i++) fprintf(f, "%d\n", i);
    fclose(f);
    expect_error(T_, file_path("many.txt"), VXL_ERR_LIMIT, "more than 65536 labels");
    /* exactly 65536 is fine */
    f = fopen(file_path("cap.txt"), "wb");
    REQUIRE(f);
    for (int i = 0; i < 65536; i++) fprintf(f, "%d\n", i);
    fclose(f);
    uint32_t n = 0;
    CHECK(vxl_label_table_load(file_path("cap.txt"), NULL, 0, &n) == VXL_OK && n == 65536);
    /* over 1 MiB: refused before parsing */
    f = fopen(file_path("big.txt"), "wb");
    REQUIRE(f);
    for (int i = 0; i < 80000; i++) fprintf(f, "# padding padding\n");
    fclose(f);
    expect_error(T_, file_path("big.txt"), VXL_ERR_LIMIT, "at most");
}

/* ------------------------------------------------------- crash replay */

/* tests/crashers/label_table of the tree this test was built in (found
 * from the executable, BUILD/tests/test_label_table), through the fuzz
 * target's own input writer and contract check. None replayed fails. */
TEST(crash_corpus_replays_within_the_contract)
{
    char exe[900];
    ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
    REQUIRE(len > 0);
    exe[len] = '\0';
    for (int up = 0; up < 3; up++) {
        char *slash = strrchr(exe, '/');
        REQUIRE(slash != NULL);
        *slash = '\0';
    }
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/tests/crashers/label_table", exe);
    char work[256];
    snprintf(work, sizeof work, "%s/replay", g_dir);
    REQUIRE(mkdir(work, 0700) == 0);
    DIR *d = opendir(dir);
    REQUIRE(d != NULL);
    int replayed = 0;
    struct dirent *ent;
    while ((ent = readdir(d)) != NULL) {
        if (ent->d_name[0] == '.') continue;
        char p[1400], path[512];
        snprintf(p, sizeof p, "%s/%s", dir, ent->d_name);
        FILE *f = fopen(p, "rb");
        if (!f) continue;
        static uint8_t buf[1 << 16];
        size_t n = fread(buf, 1, sizeof buf, f);
        fclose(f);
        REQUIRE(lt_write_input(work, buf, n, path, sizeof path) == 0);
        int rc;
        const char *why = lt_check_load(path, &rc);
        CHECKF(why == NULL, "%s: %s", ent->d_name, why);
        replayed++;
    }
    closedir(d);
    fprintf(stderr, "  replayed %d crashers from %s\n", replayed, dir);
    CHECKF(replayed > 0, "no crasher replayed from %s", dir);
}

int main(void)
{
    snprintf(g_dir, sizeof g_dir, "/tmp/vxl_labels_XXXXXX");
    if (!mkdtemp(g_dir)) {
        perror("mkdtemp");
        return 1;
    }
    RUN(freesurfer_lut_sorted_with_transparency_as_255_minus_alpha);
    RUN(slicer_ctbl_opacity_by_header_or_extension);
    RUN(itksnap_opacity_visibility_and_quoted_names);
    RUN(mricron_pair_from_either_side_and_the_palette_alone);
    RUN(names_alone_take_the_documented_default_palette);
    RUN(real_mricron_jhu_atlas_and_its_long_names);
    RUN(count_without_out_then_max_and_stride);
    RUN(names_are_cut_to_63_bytes_of_valid_utf8);
    RUN(int32_ids_and_negative_ids);
    RUN(repeated_ids_are_an_error_naming_both_lines);
    RUN(malformed_files_give_clear_errors);
    RUN(caps_on_entries_and_file_size);
    RUN(crash_corpus_replays_within_the_contract);
    nftw(g_dir, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
    return TEST_SUMMARY();
}
