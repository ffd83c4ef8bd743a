/* label_table_samples.h - one small file of every label-table format
 * vxl_label_table_load reads (csrc/io/label_table.c), shared by
 * tests/test_label_table.c (which checks what is read from them) and
 * make_seeds.c (the fuzz seeds for fuzz_label_table), so the seeds are the
 * files the tests prove are read right. No library headers: make_seeds
 * builds without them. */
#ifndef VXL_LABEL_TABLE_SAMPLES_H
#define VXL_LABEL_TABLE_SAMPLES_H

#include <stdio.h>

/* FreeSurfer: the 4th number is transparency (alpha = 255 - T), a 7th
 * column (tissue type) may follow; CRLF lines, ids out of order. */
static const char lt_freesurfer[] =
    "#$Id: FreeSurferColorLUT.txt,v 1.105 2015/07/29 nicks Exp $\r\n"
    "\r\n"
    "#No. Label Name:                            R   G   B   A\r\n"
    "17  Left-Hippocampus                        220 216  20   0\r\n"
    "0   Unknown                                   0   0   0   0\r\n"
    "2   Left-Cerebral-White-Matter              245 245 245 255   1\r\n"
    "1000    ctx-lh-unknown                       25   5  25  55\r\n";

/* 3D Slicer: opacity 0..255, named by its header comment. */
static const char lt_slicer[] =
    "# Color table file /tmp/Segmentation-label_ColorTable.ctbl\n"
    "# 4 values\n"
    "0 Background 0 0 0 0\n"
    "1 artery 216 101 79 255\n"
    "3 connective_tissue 111 184 210 128\n"
    "2 bone 241 214 145 255\n";

/* The same lines without the header: Slicer only as a .ctbl. */
static const char lt_slicer_bare[] = "1 artery 216 101 79 255\n2 bone 241 214 145 0\n";

/* ITK-SNAP: opacity 0..1, VIS, MSH, quoted names with spaces. */
static const char lt_itksnap[] =
    "################################################\n"
    "# ITK-SnAP Label Description File\n"
    "# IDX   -R-  -G-  -B-  -A--  VIS MSH  LABEL\n"
    "################################################\n"
    "    0     0    0    0        0  0  0    \"Clear Label\"\n"
    "    1   255    0    0        1  1  1    \"Left ventricle\"\n"
    "   12     0  255    0      0.5  0  1    \"Myocardium wall\"\n";

/* MRIcron's names beside an atlas: `index name [code]`, tabs or spaces. */
static const char lt_names[] = "1 Precentral_L 2001\r\n2\tPrecentral_R\r\n7 Frontal_Mid_L 2201\r\n\r\n";

/* A 768-byte MRIcron palette: 256 reds, then greens, then blues; entry i
 * is (i, 255 - i, (7 * i) & 255). */
static inline void lt_palette(unsigned char out[768])
{
    for (int i = 0; i < 256; i++) {
        out[i] = (unsigned char)i;
        out[256 + i] = (unsigned char)(255 - i);
        out[512 + i] = (unsigned char)((7 * i) & 255);
    }
}

/* Fuzz inputs: the first byte picks the file(s) the rest becomes
 * (label_table_input.h): 0 .txt, 1 .ctbl, 2 .label, 3 .lut alone, 4 a
 * .lut (the next 768 bytes) with the .txt of its stem (the rest). */
enum { LT_MODE_TXT, LT_MODE_CTBL, LT_MODE_LABEL, LT_MODE_LUT, LT_MODE_PAIR, LT_MODE_COUNT };

static inline int lt_write_seed(const char *path, unsigned char mode, const void *a, size_t na, const void *b, size_t nb)
{
    FILE *f = fopen(path, "wb");
    if (!f) return 1;
    int bad = fputc(mode, f) == EOF || fwrite(a, 1, na, f) != na || (nb && fwrite(b, 1, nb, f) != nb);
    return fclose(f) != 0 || bad;
}

#endif
