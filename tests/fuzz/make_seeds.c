/* make_seeds.c - writes the seed corpus for the fuzz targets: small valid
 * files of every format and the main variants (types, byte orders,
 * compression, geometry, pages, channels).
 *   make_seeds OUTDIR   ->  OUTDIR/{nifti,nrrd,metaimage,tiff,png,dicom,label_table,dicom_codecs,ome_xml}/seed_*
 * (dicom_codecs' JPEG seeds come from tests/fuzz/jpeg_seeds.py: dcmtk encodes them)
 * Built and run by `make fuzz-seeds` (./build.sh test / fuzz). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "fuzz/dicom_writer.h"
#include "fuzz/label_table_samples.h"
#include "fuzz/writers.h"
#include "hdr_writer.h"
#include "nifti_writer.h"

static char g_out[512];

static const char *path(const char *fmt, const char *name)
{
    static char p[1024];
    char d[768];
    snprintf(d, sizeof d, "%s/%s", g_out, fmt);
    mkdir(d, 0755);
    snprintf(p, sizeof p, "%s/%s", d, name);
    return p;
}

static int failures;
static void ok(int rc, const char *what)
{
    if (rc) {
        fprintf(stderr, "make_seeds: cannot write %s\n", what);
        failures++;
    }
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: make_seeds OUTDIR\n");
        return 2;
    }
    snprintf(g_out, sizeof g_out, "%s", argv[1]);
    mkdir(g_out, 0755);

    uint8_t u8[24];
    int16_t i16[24];
    float f32[24];
    for (int i = 0; i < 24; i++) {
        u8[i] = (uint8_t)(i * 10);
        i16[i] = (int16_t)(i * 1000 - 12000);
        f32[i] = (float)i * 0.5f - 3.0f;
    }
    void *i16_be = tw_swapped(i16, 24, 2);

    /* NIfTI: -1 and -2, native and swapped, plain and gzip */
    tnw_header h;
    tnw_init(&h, 1, 2, 4, 3, 2);
    ok(tnw_write(path("nifti", "seed_u8.nii"), &h, u8, sizeof u8), "nifti u8");
    tnw_init(&h, 1, 4, 4, 3, 2);
    h.swap = 1;
    h.sform_code = 1;
    for (int r = 0; r < 3; r++) h.srow[r][r] = 1.5;
    ok(tnw_write(path("nifti", "seed_i16_swapped.nii"), &h, i16_be, sizeof i16), "nifti i16 swapped");
    tnw_init(&h, 2, 16, 4, 3, 2);
    h.qform_code = 1;
    h.quatern[0] = 0.5;
    ok(tnw_write(path("nifti", "seed_f32_v2.nii.gz"), &h, f32, sizeof f32), "nifti f32 v2 gz");

    /* NRRD */
    ok(tw_write_header_data(path("nrrd", "seed_u8.nrrd"),
                            "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 3 2\nencoding: raw\n\n", u8, sizeof u8,
                            TW_RAW, NULL), "nrrd u8");
    ok(tw_write_header_data(path("nrrd", "seed_i16_gz_lps.nrrd"),
                            "NRRD0005\n# seed\ntype: short\ndimension: 3\nspace: left-posterior-superior\n"
                            "sizes: 4 3 2\nspace directions: (0,1.5,0) (-1,0,0) (0,0,2)\nkinds: domain domain domain\n"
                            "endian: big\nencoding: gzip\nspace origin: (1,2,3)\nkey:=value\n\n",
                            i16_be, sizeof i16, TW_GZIP, NULL), "nrrd i16 gzip");
    ok(tw_write_header_data(path("nrrd", "seed_f32_spacings.nrrd"),
                            "NRRD0004\ntype: float\ndimension: 3\nsizes: 4 3 2\nspacings: 0.5 nan 2\n"
                            "endian: little\nencoding: raw\nbyte skip: 0\n\n",
                            f32, sizeof f32, TW_RAW, NULL), "nrrd f32");
    ok(tw_write_header_data(path("nrrd", "seed_u8_4d.nrrd"),
                            "NRRD0004\ntype: uint8\ndimension: 4\nsizes: 2 3 2 2\nspace: RAS\n"
                            "space directions: (1,0,0) (0,1,0) (0,0,1) none\nencoding: raw\n\n",
                            u8, sizeof u8, TW_RAW, NULL), "nrrd 4d");

    /* MetaImage */
    ok(tw_write_header_data(path("metaimage", "seed_u8.mha"),
                            "ObjectType = Image\nNDims = 3\nDimSize = 4 3 2\nElementType = MET_UCHAR\n"
                            "ElementDataFile = LOCAL\n", u8, sizeof u8, TW_RAW, NULL), "mha u8");
    ok(tw_write_header_data(path("metaimage", "seed_f32_zlib.mha"),
                            "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
                            "CompressedData = True\nTransformMatrix = 0 1 0 -1 0 0 0 0 1\nOffset = 1 2 3\n"
                            "ElementSpacing = 0.5 1 2\nDimSize = 4 3 2\nElementType = MET_FLOAT\n"
                            "ElementDataFile = LOCAL\n", f32, sizeof f32, TW_ZLIB, NULL), "mha f32 zlib");
    ok(tw_write_header_data(path("metaimage", "seed_i16_msb.mha"),
                            "NDims = 3\nDimSize = 4 3 2\nElementByteOrderMSB = True\nElementType = MET_SHORT\n"
                            "HeaderSize = -1\nElementDataFile = LOCAL\n", i16_be, sizeof i16, TW_RAW, NULL),
       "mha i16 msb");
    /* colour: 3 channels a voxel (the colour volume's path) */
    ok(tw_write_header_data(path("metaimage", "seed_rgb_zlib.mha"),
                            "NDims = 3\nDimSize = 4 2 1\nElementNumberOfChannels = 3\nElementType = MET_UCHAR\n"
                            "CompressedData = True\nElementDataFile = LOCAL\n", u8, sizeof u8, TW_ZLIB, NULL),
       "mha rgb zlib");
    /* channels (the multi-channel volume's path): 2 and 6 a voxel, the 24 bytes of u8 */
    static const struct { const char *name, *header; int codec; } mha_channels[] = {
        {"seed_2ch.mha", "NDims = 3\nDimSize = 4 3 1\nElementNumberOfChannels = 2\nElementType = MET_UCHAR\n"
                         "ElementDataFile = LOCAL\n", TW_RAW},
        {"seed_6ch_zlib.mha", "NDims = 3\nDimSize = 2 2 1\nElementNumberOfChannels = 6\nElementType = MET_UCHAR\n"
                              "CompressedData = True\nElementDataFile = LOCAL\n", TW_ZLIB},
    };
    for (size_t i = 0; i < sizeof mha_channels / sizeof mha_channels[0]; i++)
        ok(tw_write_header_data(path("metaimage", mha_channels[i].name), mha_channels[i].header, u8, sizeof u8,
                                mha_channels[i].codec, NULL), mha_channels[i].name);

    /* TIFF */
    ok(tw_write_tiff(path("tiff", "seed_u8_pages.tif"), 4, 3, 2, 1, 8, 1, u8), "tiff u8 pages");
    ok(tw_write_tiff(path("tiff", "seed_i16.tif"), 4, 3, 1, 1, 16, 2, i16), "tiff i16");
    ok(tw_write_tiff(path("tiff", "seed_f32.tif"), 4, 3, 2, 1, 32, 3, f32), "tiff f32");
    ok(tw_write_tiff(path("tiff", "seed_rgb.tif"), 4, 2, 1, 3, 8, 1, u8), "tiff rgb");
    ok(tw_write_tiff(path("tiff", "seed_2samples.tif"), 4, 3, 1, 2, 8, 1, u8), "tiff 2 samples (channels)");

    /* OME-XML (an OME-TIFF's ImageDescription): both common orders, names
     * with entities, signed colours, a prefixed namespace */
    static const char *const ome[] = {
        "<?xml version=\"1.0\"?><OME xmlns=\"http://www.openmicroscopy.org/Schemas/OME/2016-06\"><Image ID=\"Image:0\">"
        "<Pixels DimensionOrder=\"XYZCT\" Type=\"uint16\" SizeX=\"4\" SizeY=\"3\" SizeZ=\"2\" SizeC=\"3\" "
        "SizeT=\"1\"><Channel ID=\"Channel:0:0\" Name=\"DAPI\" Color=\"65535\"/><Channel Name=\"GFP &amp; co\" "
        "Color=\"16711935\"/><Channel Name='Cy5' Color=\"-16711681\"/><TiffData/></Pixels></Image></OME>",
        "<ome:OME xmlns:ome=\"x\"><ome:Image><ome:Pixels SizeT=\"2\" SizeC=\"2\" SizeZ=\"3\" SizeY=\"1\" SizeX=\"1\" "
        "DimensionOrder=\"XYCZT\"><ome:Channel Name=\"a\"/><ome:Channel Color=\"-1\"/></ome:Pixels></ome:Image>"
        "</ome:OME>",
    };
    for (size_t i = 0; i < sizeof ome / sizeof ome[0]; i++) {
        char name[32];
        snprintf(name, sizeof name, "seed_%zu.xml", i);
        ok(tw_write(path("ome_xml", name), ome[i], strlen(ome[i]), NULL, 0), "ome_xml");
    }

    /* PNG */
    uint16_t u16[24];
    for (int i = 0; i < 24; i++) u16[i] = (uint16_t)(i * 2000);
    ok(tw_write_png(path("png", "seed_gray8.png"), 4, 3, 1, 8, u8), "png gray8");
    ok(tw_write_png(path("png", "seed_gray16.png"), 4, 3, 1, 16, u16), "png gray16");
    ok(tw_write_png(path("png", "seed_rgb8.png"), 4, 2, 3, 8, u8), "png rgb8");
    ok(tw_write_png(path("png", "seed_ga8.png"), 4, 3, 2, 8, u8), "png grey+alpha");
    /* DICOM: one slice each (the target loads the file's own series):
     * 16-bit with CT rescale, signed 12-of-16 bits oblique, 8-bit, and the
     * refused variants (JPEG syntax, multi-frame) so their paths are fuzzed */
    dcmw_slice d = dcmw_axial("1.2.826.0.1.3680043.9.7777.2", 4, 3, -20, i16, sizeof i16);
    d.has_rescale = 1;
    d.slope = 1;
    d.inter = -1024;
    d.description = "seed";
    ok(dcmw_write(path("dicom", "seed_ct16.dcm"), &d), "dicom ct16");
    d.pixel_rep = 1;
    d.bits_stored = 12;
    const double oblique[6] = {0.8, 0.6, 0, 0, 0, -1};
    memcpy(d.iop, oblique, sizeof oblique);
    ok(dcmw_write(path("dicom", "seed_signed12_oblique.dcm"), &d), "dicom signed12");
    d = dcmw_axial("1.2.3", 4, 3, 0, u8, 12);
    d.bits_alloc = 8;
    d.modality = "MR";
    ok(dcmw_write(path("dicom", "seed_u8.dcm"), &d), "dicom u8");
    d.transfer_syntax = DCMW_JPEG_BASELINE;
    ok(dcmw_write(path("dicom", "seed_jpeg.dcm"), &d), "dicom jpeg");
    d = dcmw_axial("1.2.4", 4, 3, 0, i16, sizeof i16);
    d.frames = 2;
    ok(dcmw_write(path("dicom", "seed_multiframe.dcm"), &d), "dicom multiframe");
    free(i16_be);

    /* label tables: every format's sample, the first byte picking the file */
    unsigned char pal[768];
    lt_palette(pal);
    ok(lt_write_seed(path("label_table", "seed_freesurfer"), LT_MODE_TXT, lt_freesurfer, sizeof lt_freesurfer - 1, NULL, 0),
       "label freesurfer");
    ok(lt_write_seed(path("label_table", "seed_slicer"), LT_MODE_CTBL, lt_slicer, sizeof lt_slicer - 1, NULL, 0),
       "label slicer");
    ok(lt_write_seed(path("label_table", "seed_itksnap"), LT_MODE_LABEL, lt_itksnap, sizeof lt_itksnap - 1, NULL, 0),
       "label itk-snap");
    ok(lt_write_seed(path("label_table", "seed_names"), LT_MODE_TXT, lt_names, sizeof lt_names - 1, NULL, 0),
       "label names");
    ok(lt_write_seed(path("label_table", "seed_lut"), LT_MODE_LUT, pal, sizeof pal, NULL, 0), "label lut");
    ok(lt_write_seed(path("label_table", "seed_pair"), LT_MODE_PAIR, pal, sizeof pal, lt_names, sizeof lt_names - 1),
       "label pair");
    /* DICOM RLE frames (dicom_codec_input.h's 4-byte prefix, the 64-byte
     * header, PackBits segments): 8-bit
     * 2 x 4 with every kind of run, and 16-bit 1 x 3 in two segments */
    static const uint8_t rle8[] = {1, 3, 0, 0, 1, 0, 0, 0, 64, 0, 0, 0, [68] = 2, 1, 2, 3, 0x80, 0xfd, 9, 0, 7, 0};
    static const uint8_t rle16[] = {0, 2, 1, 0, 2, 0, 0, 0, 64, 0, 0, 0, 68, 0, 0, 0, [68] = 0xff, 0x12, 0, 0x80,
                                    2, 0x34, 0xff, 0};
    ok(tw_write(path("dicom_codecs", "seed_rle_8bit"), rle8, sizeof rle8, NULL, 0), "dicom rle 8-bit");
    ok(tw_write(path("dicom_codecs", "seed_rle_16bit"), rle16, sizeof rle16, NULL, 0), "dicom rle 16-bit");

    /* Radiance World maps: run-length and flat scanlines, both row orders,
     * a width under the run-length minimum, runs and literals of every kind */
    {
        float map[40 * 6 * 3];
        for (int i = 0; i < 40 * 6; i++) {
            map[3 * i] = i % 40 < 20 ? 0.5f : 4.0f;
            map[3 * i + 1] = (float)(i / 40) * 0.1f + (float)(i % 3) * 0.01f;
            map[3 * i + 2] = i < 40 ? 1000.0f : 0.0f;
        }
        const struct {
            const char *name;
            uint32_t w, h;
            int rle, top;
        } maps[] = {{"seed_rle_top", 40, 6, 1, 1}, {"seed_rle_bottom", 40, 6, 1, 0}, {"seed_flat", 40, 6, 0, 1},
                    {"seed_narrow", 5, 3, 1, 1}, {"seed_1x1", 1, 1, 0, 1}};
        for (size_t k = 0; k < sizeof maps / sizeof maps[0]; k++) {
            size_t n = 0;
            uint8_t *b = hdr_encode(map, maps[k].w, maps[k].h, maps[k].rle, maps[k].top, &n);
            ok(b ? tw_write(path("hdr", maps[k].name), b, n, NULL, 0) : 1, "hdr");
            free(b);
        }
    }

    return failures ? 1 : 0;
}
