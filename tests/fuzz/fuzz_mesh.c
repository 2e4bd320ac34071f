/* libFuzzer target: fogvol_validate_mesh on arbitrary vertex and index data.
   Input layout: u16 vertex count, u16 selector (bit 0: stride 24, bit 1: indices
   mostly in range, bit 2: position at offset 12 of the 24-byte vertex, bit 3:
   16-bit indices, bit 4: weld with distance 1e-3), then floats and u32
   indices taken from the rest. Checks: no out-of-bounds access (ASan), no
   UB (UBSan), and invariants of the report that hold for any input. */
#ifndef FOGVOL_TEST_LINKED /* make test links fogvol's implementation built once (Makefile: FUZZ_IMPL) */
#define FOGVOL_IMPLEMENTATION
#endif
#define FOGVOL_NO_GL
#include "fogvol.h"
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fogvol_mesh_desc d;
    fogvol_mesh_report r;
    fogvol_result res;
    uint16_t nv, sel;
    int stride, nflt, ni, i;
    float *pos;
    uint32_t *idx;
    uint16_t *idx16 = NULL;
    if (size < 4) return 0;
    memcpy(&nv, data, 2);
    memcpy(&sel, data + 2, 2);
    data += 4;
    size -= 4;
    nv = (uint16_t)(nv % 512 + 1);
    stride = (sel & 1) ? 24 : 12;
    nflt = nv * (stride / 4);
    if (size < (size_t)nflt * 4) return 0;
    /* exactly sized buffers so ASan sees any read past them */
    pos = (float *)malloc((size_t)nflt * 4);
    memcpy(pos, data, (size_t)nflt * 4);
    data += (size_t)nflt * 4;
    size -= (size_t)nflt * 4;
    ni = (int)(size / 4) / 3 * 3;
    if (ni == 0) {
        free(pos);
        return 0;
    }
    idx = (uint32_t *)malloc((size_t)ni * 4);
    memcpy(idx, data, (size_t)ni * 4);
    if (sel & 2)
        for (i = 0; i < ni; ++i) idx[i] %= (uint32_t)nv + 2u; /* mostly in range, some past the end */
    memset(&d, 0, sizeof d);
    d.positions = pos;
    d.vertex_count = nv;
    d.stride = stride;
    d.offset = (sel & 4) && stride == 24 ? 12 : 0;
    d.indices = idx;
    d.index_count = ni;
    if (sel & 8) { /* exactly sized 16-bit copy */
        idx16 = (uint16_t *)malloc((size_t)ni * 2);
        for (i = 0; i < ni; ++i) idx16[i] = (uint16_t)idx[i];
        d.index_type = FOGVOL_INDEX_UINT16;
        d.indices16 = idx16;
        d.indices = NULL;
    }
    if (sel & 16) d.weld_distance = 1e-3f;
    res = fogvol_validate_mesh(&d, NULL, &r);
    if (res != FOGVOL_SUCCESS && res != FOGVOL_ERROR_INVALID_MESH) abort();
    if (r.triangles != ni / 3 || r.vertices + r.welded_vertices != nv) abort();
    if (r.welded_vertices < 0 || r.welded_vertices >= nv || (!(sel & 16) && r.welded_vertices)) abort();
    if (r.open_edges < 0 || r.flipped_faces < 0 || r.flipped_faces > r.triangles) abort();
    if (r.degenerate_triangles > r.triangles || r.nonfinite_vertices > nv) abort();
    if ((res == FOGVOL_SUCCESS) != (r.valid != 0)) abort();
    if (r.valid && (!r.closed || !r.consistent || r.out_of_range_indices || r.nonfinite_vertices)) abort();
    free(pos);
    free(idx);
    free(idx16);
    return 0;
}
