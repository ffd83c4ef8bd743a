/* brick_source.c - what every brick source shares (brick_source.h). */
#include "brick_source.h"

#include <stdlib.h>

void vxl_brick_source_free(vxl_brick_source *s)
{
    if (!s) return;
    if (s->ops && s->ops->close) s->ops->close(s);
    free(s->minmax);
    free(s);
}
