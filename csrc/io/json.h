/* json.h - a small strict JSON parser for metadata files (OME-Zarr's
 * .zattrs/.zarray/zarr.json): RFC 8259 only (no comments, no NaN literals,
 * no trailing commas), bounded input size and nesting depth, every node in
 * one array whose size is bounded by the input's length, so hostile input
 * costs at most a few times its own size and never deep recursion. */
#ifndef VXL_JSON_H
#define VXL_JSON_H

#include <stddef.h>
#include <stdint.h>

#define VXL_JSON_MAX_BYTES (1u << 20) /* metadata files are a few KiB */
#define VXL_JSON_MAX_DEPTH 64

enum { VXL_JSON_NULL, VXL_JSON_FALSE, VXL_JSON_TRUE, VXL_JSON_NUMBER, VXL_JSON_STRING, VXL_JSON_ARRAY,
       VXL_JSON_OBJECT };

typedef struct vxl_json {
    int type;
    double num;          /* VXL_JSON_NUMBER */
    int is_integer;      /* the number was written without fraction or exponent */
    const char *str;     /* VXL_JSON_STRING: decoded, NUL-terminated (no embedded NUL allowed) */
    const char *key;     /* member name when the parent is an object */
    int32_t first, next; /* first child, next sibling: indices into the document, -1 = none */
    uint32_t count;      /* children of an array or object */
} vxl_json;

typedef struct vxl_json_doc {
    vxl_json *nodes; /* nodes[0] is the root */
    uint32_t n;
    char *text;      /* the decoded copy strings point into */
} vxl_json_doc;

/* Parses text[0..len). On failure returns -1 and writes a message (with the
 * byte offset) into err. The document owns copies of everything. */
int vxl_json_parse(const char *text, size_t len, vxl_json_doc *doc, char *err, size_t err_size);
void vxl_json_free(vxl_json_doc *doc);

/* Navigation; NULL when absent or when v is NULL or of another type. */
const vxl_json *vxl_json_get(const vxl_json_doc *d, const vxl_json *obj, const char *key);
const vxl_json *vxl_json_at(const vxl_json_doc *d, const vxl_json *arr, uint32_t i);
/* v's string when it is one, else NULL. */
const char *vxl_json_string(const vxl_json *v);

#endif
