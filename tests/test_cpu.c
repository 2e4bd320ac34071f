/* CPU self-tests of fogvol.h (the ">>cpu" section): encoding table, shader
   constants, the reference depth encoder, saturating sums and decode, the
   dither, the lookup textures, the colour ramps and mesh validation.

   Every check is against INDEPENDENT ground truth: values worked out by hand
   (the arithmetic is in the comments), values computed here by a separate,
   simpler method (integer models, closed-form volumes, exp() in double), or
   properties that follow from the spec (bounds, counts).

   Build (from the repository root):
     gcc -std=c99 -O1 -g -Wall -Wextra -pedantic -Werror -fsanitize=address,undefined \
         -I. tests/test_cpu.c -o /tmp/test_cpu -lcmocka -lm && /tmp/test_cpu
     g++ -x c++ -std=c++11 (same flags) ...

   Notation: L bits per channel, N = 2^L, N^3 blue LSBs over [0,1), D dither
   rows (= blue-ramp texels per blue LSB). For encoded bytes (R,G,B,A) the
   integer value is V = R*N^2 + G*N + B - A*N and decode = V / N^3.
   1 LSB = 1/N^3 (in units of far - near). */

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#ifdef __cplusplus
extern "C" { /* cmocka 1.1.5's header has no C++ guards of its own */
#endif
#include <cmocka.h>
#ifdef __cplusplus
}
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef FOGVOL_TEST_LINKED /* make test links fogvol_impl.o / fogvol_impl_san.o (Makefile: LINKED_TESTS) */
#define FOGVOL_IMPLEMENTATION
#endif
#define FOGVOL_NO_GL
#include "../fogvol.h"
#include "shapes.h"

#define PI_D 3.14159265358979323846

/* ------------------------------------------------------------------------ */
/* helpers                                                                  */
/* ------------------------------------------------------------------------ */

#define CHECK_NEAR(a, b, tol)                                                                      \
    do {                                                                                           \
        double a_ = (double)(a), b_ = (double)(b), t_ = (double)(tol);                             \
        if (!(fabs(a_ - b_) <= t_)) {                                                              \
            print_error("%s:%d: %s = %.17g, expected %s = %.17g (tolerance %g)\n", __FILE__,       \
                        __LINE__, #a, a_, #b, b_, t_);                                             \
            fail();                                                                                \
        }                                                                                          \
    } while (0)

/* assert with a formatted message (cmocka 1.1.5 has no portable fail_msg under -pedantic) */
#define CHECK_MSG(cond, ...)                                                                       \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            print_error("%s:%d: check failed: %s\n  ", __FILE__, __LINE__, #cond);                 \
            print_error(__VA_ARGS__);                                                              \
            print_error("\n");                                                                     \
            fail();                                                                                \
        }                                                                                          \
    } while (0)

/* xorshift64* : fixed seeds, reproducible everywhere */
typedef struct rng_t {
    uint64_t s;
} rng_t;

static uint64_t rng_next(rng_t *r)
{
    r->s ^= r->s >> 12;
    r->s ^= r->s << 25;
    r->s ^= r->s >> 27;
    return r->s * UINT64_C(2685821657736338717);
}

static double rng_unit(rng_t *r) /* [0, 1) with 53 random bits */
{
    return (double)(rng_next(r) >> 11) * (1.0 / 9007199254740992.0);
}

static int rng_int(rng_t *r, int n) /* [0, n) */
{
    return (int)(rng_next(r) % (uint64_t)n);
}

static fogvol_encoding make_enc(int bits)
{
    fogvol_encoding e;
    memset(&e, 0, sizeof e);
    assert_int_equal(fogvol_encoding_init(bits, &e), FOGVOL_SUCCESS);
    return e;
}

/* Integer value of encoded bytes, computed here (not by the library). */
static long long value_of(int n, const unsigned char b[4])
{
    return (long long)b[0] * n * n + (long long)b[1] * n + b[2] - (long long)b[3] * n;
}

static long long floor_div(long long a, long long b) /* b > 0 */
{
    long long q = a / b;
    if ((a % b) != 0 && a < 0) --q;
    return q;
}

/* Threshold numerator of dither row r, straight from the spec: k = (r + D/2) mod D. */
static int row_k(int r, int dsteps) { return (r + dsteps / 2) % dsteps; }

/* The model of the whole encoder in one line (see the header comment): for
   x = d*N^3 (blue LSBs, unclamped range [0, N^3 - 1.5]), the blue texel
   quantises x to F/D with F = floor(x*D), and row r rounds with threshold k/D:
       V = floor(F/D + k/D) = floor_div(F + k, D).                           */
static long long model_value(double x, int k, int dsteps)
{
    long long f = (long long)floor(x * dsteps);
    return floor_div(f + k, dsteps);
}

static void expect_bytes(const fogvol_encoding *e, double d, int row, int r, int g, int b, int a)
{
    unsigned char out[4] = {99, 99, 99, 99};
    assert_int_equal(fogvol_encode_depth(e, d, row, out), FOGVOL_SUCCESS);
    if (out[0] != r || out[1] != g || out[2] != b || out[3] != a) {
        print_error("L=%d d=%.17g row %d: got (%d,%d,%d,%d), expected (%d,%d,%d,%d)\n", e->bits, d, row,
                    out[0], out[1], out[2], out[3], r, g, b, a);
        fail();
    }
}

/* ------------------------------------------------------------------------ */
/* 1. encoding table                                                        */
/* ------------------------------------------------------------------------ */

static void test_encoding_table(void **state)
{
    /* Figure 3 of the seed: bits per channel -> precision, faces. */
    static const int fig3[][3] = {{4, 12, 16}, {5, 15, 8}, {3, 9, 32}, {7, 21, 2}};
    fogvol_encoding rows[9];
    fogvol_encoding e;
    int i, L, f, p;
    (void)state;

    memset(rows, 0x5a, sizeof rows);
    assert_int_equal(fogvol_encoding_table(NULL, 0), 8);
    assert_int_equal(fogvol_encoding_table(rows, 9), 8);
    for (i = 0; i < 4; ++i) {
        const fogvol_encoding *r = &rows[fig3[i][0] - 1];
        assert_int_equal(r->bits, fig3[i][0]);
        assert_int_equal(r->precision_bits, fig3[i][1]);
        assert_int_equal(r->max_faces, fig3[i][2]);
    }
    /* all L = 1..8: N = 2^L, precision 3L, faces 2^(8-L), single-target 2^(7-L) (0 for L = 8),
       D = 32 unless the blue ramp N*D would exceed 2048 texels: L=7 -> 16, L=8 -> 8. */
    {
        static const int faces[8] = {128, 64, 32, 16, 8, 4, 2, 1};
        static const int single[8] = {64, 32, 16, 8, 4, 2, 1, 0};
        static const int dsteps[8] = {32, 32, 32, 32, 32, 32, 16, 8};
        for (L = 1; L <= 8; ++L) {
            const fogvol_encoding *r = &rows[L - 1];
            assert_int_equal(r->bits, L);
            assert_int_equal(r->levels, 1 << L);
            assert_int_equal(r->precision_bits, 3 * L);
            assert_int_equal(r->max_faces, faces[L - 1]);
            assert_int_equal(r->max_faces_single, single[L - 1]);
            assert_int_equal(r->dither_steps, dsteps[L - 1]);
            assert_true(r->levels * r->dither_steps <= 2048);
        }
    }
    /* row 9 untouched (only 8 rows exist); capacity 3 writes exactly 3 rows */
    {
        unsigned char canary[sizeof(fogvol_encoding)];
        memset(canary, 0x5a, sizeof canary);
        assert_memory_equal(&rows[8], canary, sizeof canary);
        memset(rows, 0x5a, sizeof rows);
        assert_int_equal(fogvol_encoding_table(rows, 3), 8);
        assert_int_equal(rows[2].bits, 3);
        assert_memory_equal(&rows[3], canary, sizeof canary);
        assert_int_equal(fogvol_encoding_table(rows, -1), 8);
    }

    /* from_faces: the most precise L with 2^(8-L) >= faces */
    assert_int_equal(fogvol_encoding_from_faces(16, &e), FOGVOL_SUCCESS);
    assert_int_equal(e.bits, 4);
    assert_int_equal(fogvol_encoding_from_faces(17, &e), FOGVOL_SUCCESS);
    assert_int_equal(e.bits, 3);
    assert_int_equal(fogvol_encoding_from_faces(8, &e), FOGVOL_SUCCESS);
    assert_int_equal(e.bits, 5);
    assert_int_equal(e.max_faces, 8);
    assert_int_equal(fogvol_encoding_from_faces(9, &e), FOGVOL_SUCCESS);
    assert_int_equal(e.bits, 4);
    assert_int_equal(fogvol_encoding_from_faces(1, &e), FOGVOL_SUCCESS);
    assert_int_equal(e.bits, 8);
    assert_int_equal(fogvol_encoding_from_faces(2, &e), FOGVOL_SUCCESS);
    assert_int_equal(e.bits, 7);
    assert_int_equal(fogvol_encoding_from_faces(128, &e), FOGVOL_SUCCESS);
    assert_int_equal(e.bits, 1);
    /* every count 1..128 against a brute-force search written here */
    for (f = 1; f <= 128; ++f) {
        int want = 0;
        for (L = 1; L <= 8; ++L)
            if ((256 >> L) >= f) want = L; /* keep the largest L that still fits */
        assert_int_equal(fogvol_encoding_from_faces(f, &e), FOGVOL_SUCCESS);
        assert_int_equal(e.bits, want);
        assert_true(e.max_faces >= f);
    }
    /* Rejections. Below the documented range 1..128: INVALID_ARGUMENT; above it
       (a count no encoding can sum): UNSUPPORTED. */
    assert_int_equal(fogvol_encoding_from_faces(0, &e), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_encoding_from_faces(-3, &e), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_encoding_from_faces(129, &e), FOGVOL_ERROR_UNSUPPORTED);
    assert_int_equal(fogvol_encoding_from_faces(100000, &e), FOGVOL_ERROR_UNSUPPORTED);
    assert_int_equal(fogvol_encoding_from_faces(16, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);

    /* from_precision: the fewest bits (most faces) with 3L >= precision */
    assert_int_equal(fogvol_encoding_from_precision(12, &e), FOGVOL_SUCCESS);
    assert_int_equal(e.bits, 4);
    assert_int_equal(fogvol_encoding_from_precision(13, &e), FOGVOL_SUCCESS);
    assert_int_equal(e.bits, 5);
    assert_int_equal(fogvol_encoding_from_precision(24, &e), FOGVOL_SUCCESS);
    assert_int_equal(e.bits, 8);
    assert_int_equal(fogvol_encoding_from_precision(1, &e), FOGVOL_SUCCESS);
    assert_int_equal(e.bits, 1);
    assert_int_equal(fogvol_encoding_from_precision(4, &e), FOGVOL_SUCCESS);
    assert_int_equal(e.bits, 2);
    for (p = 1; p <= 24; ++p) {
        assert_int_equal(fogvol_encoding_from_precision(p, &e), FOGVOL_SUCCESS);
        assert_int_equal(e.bits, (p + 2) / 3); /* ceil(p/3) */
    }
    assert_int_equal(fogvol_encoding_from_precision(0, &e), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_encoding_from_precision(-12, &e), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_encoding_from_precision(25, &e), FOGVOL_ERROR_UNSUPPORTED);
    assert_int_equal(fogvol_encoding_from_precision(12, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);

    assert_int_equal(fogvol_encoding_init(0, &e), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_encoding_init(9, &e), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_encoding_init(4, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
}

/* ------------------------------------------------------------------------ */
/* 2. shader constants                                                      */
/* ------------------------------------------------------------------------ */

static void test_constants(void **state)
{
    fogvol_encoding e = make_enc(4), bad;
    fogvol_constants c;
    (void)state;

    /* near 1, far 101, L = 4: range 100.
       near_far = (1/100, -1/100); ramp_scale = (1, 16, 256, 0);
       scale = 100*255/16 = 1593.75; decode = (1593.75, 99.609375, 6.2255859375, -99.609375);
       depth_offset = 1/4096; depth_max = 1 - 1.5/4096; lsb = 1593.75/(255*256) = 100/4096. */
    assert_int_equal(fogvol_compute_constants(&e, 1.0f, 101.0f, 0.0f, &c), FOGVOL_SUCCESS);
    CHECK_NEAR(c.near_far[0], 0.01, 1e-9);
    CHECK_NEAR(c.near_far[1], -0.01, 1e-9);
    /* d = w*near_far[0] + near_far[1]: w = near -> 0, w = far -> 1, w = 51 -> 0.5 */
    CHECK_NEAR(1.0 * c.near_far[0] + c.near_far[1], 0.0, 1e-7);
    CHECK_NEAR(101.0 * c.near_far[0] + c.near_far[1], 1.0, 1e-6);
    CHECK_NEAR(51.0 * c.near_far[0] + c.near_far[1], 0.5, 1e-6);
    CHECK_NEAR(c.ramp_scale[0], 1.0, 0);
    CHECK_NEAR(c.ramp_scale[1], 16.0, 0);
    CHECK_NEAR(c.ramp_scale[2], 256.0, 0);
    CHECK_NEAR(c.ramp_scale[3], 0.0, 0);
    CHECK_NEAR(c.scale, 1593.75, 0);
    CHECK_NEAR(c.decode[0], 1593.75, 0);
    CHECK_NEAR(c.decode[1], 99.609375, 0);
    CHECK_NEAR(c.decode[2], 6.2255859375, 0);
    CHECK_NEAR(c.decode[3], -99.609375, 0);
    CHECK_NEAR(c.depth_offset, 1.0 / 4096.0, 0);
    CHECK_NEAR(c.depth_max, 1.0 - 1.5 / 4096.0, 1e-7);
    CHECK_NEAR(c.lsb, 100.0 / 4096.0, 1e-9);
    CHECK_NEAR(c.bias[0], 128.0 / 255.0, 1e-7);
    CHECK_NEAR(c.bias[1], 128.0 / 255.0, 1e-7);
    CHECK_NEAR(c.bias[2], 128.0 / 255.0, 1e-7);
    CHECK_NEAR(c.bias[3], 0.0, 0);
    /* bias_decoded = dot(bias, decode) = 128/255 * 1593.75 * (1 + 1/16 + 1/256)
                    = 800 * 1.06640625 = 853.125 world units */
    CHECK_NEAR(c.bias_decoded, 853.125, 1e-3);
    CHECK_NEAR(c.dither_rows, 32.0, 0);

    /* Decode weights against the world: bytes (3,14,8,0) are V = 1000 LSB -> 1000/4096 of the
       range = 24.4140625 world units; the shader computes dot(bytes/255, decode). */
    CHECK_NEAR((3.0 * c.decode[0] + 14.0 * c.decode[1] + 8.0 * c.decode[2]) / 255.0, 24.4140625, 1e-4);
    /* a borrow: (4,0,15,1) is V = 1024 + 15 - 16 = 1023 -> 1023*100/4096 = 24.975585937.. */
    CHECK_NEAR((4.0 * c.decode[0] + 15.0 * c.decode[2] + 1.0 * c.decode[3]) / 255.0, 1023.0 * 100.0 / 4096.0,
               1e-4);

    /* explicit scale 2, L = 5 (N = 32): decode = 2*(1, 1/32, 1/1024, -1/32); lsb = 2/(255*1024) */
    {
        fogvol_encoding e5 = make_enc(5);
        assert_int_equal(fogvol_compute_constants(&e5, 0.5f, 10.5f, 2.0f, &c), FOGVOL_SUCCESS);
        CHECK_NEAR(c.scale, 2.0, 0);
        CHECK_NEAR(c.decode[0], 2.0, 0);
        CHECK_NEAR(c.decode[1], 0.0625, 0);
        CHECK_NEAR(c.decode[2], 2.0 / 1024.0, 0);
        CHECK_NEAR(c.decode[3], -0.0625, 0);
        CHECK_NEAR(c.near_far[0], 0.1, 1e-8);
        CHECK_NEAR(c.near_far[1], -0.05, 1e-8);
        CHECK_NEAR(c.ramp_scale[1], 32.0, 0);
        CHECK_NEAR(c.ramp_scale[2], 1024.0, 0);
        CHECK_NEAR(c.depth_offset, 1.0 / 32768.0, 0);
        CHECK_NEAR(c.lsb, 2.0 / (255.0 * 1024.0), 1e-12);
    }

    /* invalid inputs */
    assert_int_equal(fogvol_compute_constants(&e, 5.0f, 5.0f, 0.0f, &c), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_compute_constants(&e, 10.0f, 5.0f, 0.0f, &c), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_compute_constants(&e, (float)NAN, 5.0f, 0.0f, &c), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_compute_constants(&e, 1.0f, (float)NAN, 0.0f, &c), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_compute_constants(&e, 1.0f, (float)INFINITY, 0.0f, &c),
                     FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_compute_constants(&e, 1.0f, 5.0f, (float)NAN, &c), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_compute_constants(&e, 1.0f, 5.0f, -1.0f, &c), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_compute_constants(NULL, 1.0f, 5.0f, 0.0f, &c), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_compute_constants(&e, 1.0f, 5.0f, 0.0f, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    bad = e;
    bad.levels = 15; /* inconsistent with bits = 4 */
    assert_int_equal(fogvol_compute_constants(&bad, 1.0f, 5.0f, 0.0f, &c), FOGVOL_ERROR_INVALID_ARGUMENT);
    bad = e;
    bad.bits = 0;
    assert_int_equal(fogvol_compute_constants(&bad, 1.0f, 5.0f, 0.0f, &c), FOGVOL_ERROR_INVALID_ARGUMENT);
}

/* ------------------------------------------------------------------------ */
/* 3. hand-worked encodings                                                 */
/* ------------------------------------------------------------------------ */

/* Rule (header): u = clamp(d, 0, 1 - 1.5/N^3) + 1/N^3, T1 = u*N^3, h = floor(T1/N),
   R = (h/N)%N, G = h%N, x = floor(T1*D) mod N*D, k = (row + D/2)%D,
   q = floor((x+k)/D) - 1, q < 0 -> (B,A) = (q+N, 1) else (q, 0). */
static void test_hand_encodings(void **state)
{
    fogvol_encoding e2 = make_enc(2), e4 = make_enc(4), e5 = make_enc(5);
    unsigned char out[4];
    (void)state;

    /* ---- L = 2: N = 4, N^3 = 64, D = 32 (N*D = 128) ---- */
    /* Figure 4: d = 0.75: T1 = 48 + 1 = 49, h = floor(49/4) = 12 -> R = 3, G = 0;
       x = 49*32 mod 128 = 1568 - 1536 = 32; k = 16: q = floor(48/32) - 1 = 0 -> (3,0,0,0). V = 48. */
    expect_bytes(&e2, 0.75, 0, 3, 0, 0, 0);
    /* Figure 4: d = 1.0 clamps to 1 - 1.5/64 = 62.5/64: T1 = 63.5, h = 15 -> R = 3, G = 3;
       x = 2032 mod 128 = 112, q = floor(128/32) - 1 = 3 -> (3,3,3,0) = 63, the largest value. */
    expect_bytes(&e2, 1.0, 0, 3, 3, 3, 0);
    /* d = 0.3: d*64 = 19.2 (round -> 19); T1 = 20.2, h = 5 -> R = 1, G = 1;
       x = floor(646.4) = 646 mod 128 = 6, q = floor(22/32) - 1 = -1 -> B = 3, A = 1:
       (1,1,3,1) = 16 + 4 + 3 - 4 = 19 (the borrow form). */
    expect_bytes(&e2, 0.3, 0, 1, 1, 3, 1);
    /* d = 10.75/64: T1 = 11.75, h = 2 -> (0,2); x = 376 mod 128 = 120.
       row 0 (k = 16): q = floor(136/32) - 1 = 3 -> (0,2,3,0) = 11 = round(10.75).
       row 23 (k = 7): q = floor(127/32) - 1 = 2 -> (0,2,2,0) = 10 (10.75 + 7/32 < 11: rounds down).
       row 24 (k = 8): q = floor(128/32) - 1 = 3 -> (0,2,3,0) = 11 (10.75 + 8/32 = 11: rounds up). */
    expect_bytes(&e2, 10.75 / 64.0, 0, 0, 2, 3, 0);
    expect_bytes(&e2, 10.75 / 64.0, 23, 0, 2, 2, 0);
    expect_bytes(&e2, 10.75 / 64.0, 24, 0, 2, 3, 0);
    /* d = 0: T1 = 1, h = 0, x = 32, q = floor(48/32) - 1 = 0 -> (0,0,0,0) for row 0;
       row 16 (k = 0): q = floor(32/32) - 1 = 0 -> also 0: nothing below zero. */
    expect_bytes(&e2, 0.0, 0, 0, 0, 0, 0);
    expect_bytes(&e2, 0.0, 16, 0, 0, 0, 0);

    /* ---- L = 4: N = 16, N^3 = 4096, D = 32 (N*D = 512) ---- */
    /* d = 0.5: T1 = 2049, h = 128 -> R = 8, G = 0; x = 65568 mod 512 = 32, q = 0 -> (8,0,0,0). */
    expect_bytes(&e4, 0.5, 0, 8, 0, 0, 0);
    /* d = 1000.4/4096: T1 = 1001.4, h = floor(62.5875) = 62 -> R = 3, G = 14;
       x = floor(32044.8) = 32044 - 62*512 = 300, q = floor(316/32) - 1 = 8 -> (3,14,8,0) = 1000. */
    expect_bytes(&e4, 1000.4 / 4096.0, 0, 3, 14, 8, 0);
    /* d = 1024.2/4096: T1 = 1025.2, h = floor(64.075) = 64 -> R = 4, G = 0;
       x = floor(32806.4) = 32806 - 32768 = 38, q = floor(54/32) - 1 = 0 -> (4,0,0,0) = 1024.
       Rounding down onto a period start does NOT borrow: T1 is already past the start. */
    expect_bytes(&e4, 1024.2 / 4096.0, 0, 4, 0, 0, 0);
    /* d = 1023.25/4096 (rounds DOWN to 1023, but T1 = 1024.25 lies in the next blue period):
       h = floor(64.015625) = 64 -> R = 4, G = 0; x = 32776 - 32768 = 8,
       q = floor(24/32) - 1 = -1 -> B = 15, A = 1: (4,0,15,1) = 1024 + 15 - 16 = 1023. */
    expect_bytes(&e4, 1023.25 / 4096.0, 0, 4, 0, 15, 1);
    /* d = 1023.75/4096 rounds up: T1 = 1024.75, h = 64, x = 32792 - 32768 = 24,
       q = floor(40/32) - 1 = 0 -> (4,0,0,0) = 1024. */
    expect_bytes(&e4, 1023.75 / 4096.0, 0, 4, 0, 0, 0);
    /* dithered row 16 (k = 0, truncation): d = 1023.875/4096: T1 = 1024.875, h = 64;
       x = 32796 - 32768 = 28, q = floor(28/32) - 1 = -1 -> (4,0,15,1) = 1023 = floor(1023.875). */
    expect_bytes(&e4, 1023.875 / 4096.0, 16, 4, 0, 15, 1);
    /* row 31 (k = 15, threshold 15/32): same d: q = floor(43/32) - 1 = 0 -> (4,0,0,0) = 1024
       (1023.875 + 15/32 >= 1024). Row 8 (k = 24): also 1024. Row 17 (k = 1): floor(1023.875 + 1/32)
       = 1023 -> x + k = 29 < 32 -> (4,0,15,1). */
    expect_bytes(&e4, 1023.875 / 4096.0, 31, 4, 0, 0, 0);
    expect_bytes(&e4, 1023.875 / 4096.0, 8, 4, 0, 0, 0);
    expect_bytes(&e4, 1023.875 / 4096.0, 17, 4, 0, 15, 1);
    /* clamps: d < 0 encodes 0; d >= 1 - 1.5/4096 encodes the top: row 0 -> 4095 = (15,15,15,0);
       row 16 (k = 0) -> floor(4094.5) = 4094: T1 = 4095.5, h = 255, x = 131056 - 130560 = 496,
       q = floor(496/32) - 1 = 14 -> (15,15,14,0). */
    expect_bytes(&e4, -0.25, 0, 0, 0, 0, 0);
    expect_bytes(&e4, -1e300, 0, 0, 0, 0, 0);
    expect_bytes(&e4, 1.0, 0, 15, 15, 15, 0);
    expect_bytes(&e4, 2.0, 0, 15, 15, 15, 0);
    expect_bytes(&e4, 1e300, 0, 15, 15, 15, 0);
    expect_bytes(&e4, 1.0, 16, 15, 15, 14, 0);
    expect_bytes(&e4, 1.0 - 1.5 / 4096.0, 0, 15, 15, 15, 0);

    /* ---- L = 5: N = 32, N^3 = 32768, D = 32 (N*D = 1024) ---- */
    /* d = 0.5 -> V = 16384 = 16*1024 -> (16,0,0,0). */
    expect_bytes(&e5, 0.5, 0, 16, 0, 0, 0);
    /* d = 12345.5/32768: an exact tie, row 0 rounds half up to 12346 = 12*1024 + 1*32 + 26.
       T1 = 12346.5, h = floor(385.83) = 385 -> R = 12, G = 1; x = 395088 - 385*1024 = 848,
       q = floor(864/32) - 1 = 26 -> (12,1,26,0). */
    expect_bytes(&e5, 12345.5 / 32768.0, 0, 12, 1, 26, 0);
    /* d = 31.25/32768 -> 31: T1 = 32.25, h = 1 -> (0,1); x = 1032 mod 1024 = 8,
       q = floor(24/32) - 1 = -1 -> (0,1,31,1) = 32 + 31 - 32 = 31. */
    expect_bytes(&e5, 31.25 / 32768.0, 0, 0, 1, 31, 1);
    /* d = 1023.75/32768 -> 1024 = (1,0,0,0): T1 = 1024.75, h = 32 -> R = 1, G = 0;
       x = 32792 - 32768 = 24, q = floor(40/32) - 1 = 0. */
    expect_bytes(&e5, 1023.75 / 32768.0, 0, 1, 0, 0, 0);
    /* d = 1: top 32767 = (31,31,31,0). */
    expect_bytes(&e5, 1.0, 0, 31, 31, 31, 0);

    /* bad arguments */
    assert_int_equal(fogvol_encode_depth(&e4, NAN, 0, out), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_encode_depth(&e4, INFINITY, 0, out), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_encode_depth(&e4, 0.5, -1, out), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_encode_depth(&e4, 0.5, 32, out), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_encode_depth(&e4, 0.5, 0, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_encode_depth(NULL, 0.5, 0, out), FOGVOL_ERROR_INVALID_ARGUMENT);

    /* decode of the hand values (independent: V/N^3) */
    {
        static const unsigned char a[4] = {3, 14, 8, 0}, b[4] = {4, 0, 15, 1}, z[4] = {0, 0, 0, 0};
        CHECK_NEAR(fogvol_decode(&e4, a), 1000.0 / 4096.0, 0);
        CHECK_NEAR(fogvol_decode(&e4, b), 1023.0 / 4096.0, 0);
        CHECK_NEAR(fogvol_decode(&e4, z), 0.0, 0);
        /* decode is linear in the bytes, any values: (200,100,50,7) = 200/16 + 100/256 + 50/4096 - 7/256 */
        {
            static const unsigned char s[4] = {200, 100, 50, 7};
            CHECK_NEAR(fogvol_decode(&e4, s), 12.5 + 100.0 / 256.0 + 50.0 / 4096.0 - 7.0 / 256.0, 0);
        }
    }
}

/* ------------------------------------------------------------------------ */
/* 4. sums of encoded faces                                                 */
/* ------------------------------------------------------------------------ */

#define MAX_SUM_FACES 300

/* Error bound of one encoded face, in LSB, for x = d*N^3.
   Row 0 rounds to nearest: |V - x| <= 0.5 (V = floor(Q + 1/2), Q = floor(xD)/D in (x - 1/D, x],
   and V - Q is a multiple of 1/D in [-1/2 + 1/D, 1/2]).
   A dithered row: V = floor(Q + k/D) with 0 <= k < D, so V - x lies in (-1, 1): < 1 LSB.
   Above the clamp, x > N^3 - 1.5, the encoder sees N^3 - 1.5 instead of x: add the excess. */
static double face_bound(double x, double n3, int dither)
{
    double excess = x - (n3 - 1.5);
    return (dither ? 1.0 : 0.5) + (excess > 0 ? excess : 0.0);
}

static void test_sums(void **state)
{
    static unsigned char back[MAX_SUM_FACES * 4], front[MAX_SUM_FACES * 4];
    rng_t rng;
    int L;
    (void)state;
    rng.s = UINT64_C(0x9e3779b97f4a7c15);

    /* saturating add by hand: 200+100 -> 255 (saturated), 10+20 -> 30 */
    {
        unsigned char acc[4] = {200, 10, 0, 255};
        static const unsigned char v1[4] = {100, 20, 0, 0}, v0[4] = {1, 1, 1, 0};
        assert_int_equal(fogvol_sum_rgba8(v1, acc), 1);
        assert_int_equal(acc[0], 255);
        assert_int_equal(acc[1], 30);
        assert_int_equal(acc[2], 0);
        assert_int_equal(acc[3], 255);
        acc[0] = 10;
        assert_int_equal(fogvol_sum_rgba8(v0, acc), 0); /* 255 + 0 in alpha: not saturated */
        assert_int_equal(acc[0], 11);
    }

    for (L = 1; L <= 8; ++L) {
        fogvol_encoding e = make_enc(L);
        const int n = e.levels, dsteps = e.dither_steps;
        const double n3 = (double)n * n * n;
        double worst0 = 0, worstd = 0, ratio = 0, meand = 0;
        int trial, trials = 1500, cnt_d = 0;
        for (trial = 0; trial < trials; ++trial) {
            const int dither = trial & 1;
            const int k = 1 + rng_int(&rng, e.max_faces);
            double exact = 0, diff, err;
            long long vb = 0, vf = 0;
            unsigned char sb[4], sf[4];
            int i, satb = -1, satf = -1;
            double allow = 0;
            for (i = 0; i < k; ++i) {
                double db = rng_unit(&rng), df = rng_unit(&rng);
                int rb = dither ? rng_int(&rng, dsteps) : 0, rf = dither ? rng_int(&rng, dsteps) : 0;
                assert_int_equal(fogvol_encode_depth(&e, db, rb, back + 4 * i), FOGVOL_SUCCESS);
                assert_int_equal(fogvol_encode_depth(&e, df, rf, front + 4 * i), FOGVOL_SUCCESS);
                vb += value_of(n, back + 4 * i);
                vf += value_of(n, front + 4 * i);
                exact += db - df;
                allow += face_bound(db * n3, n3, dither) + face_bound(df * n3, n3, dither);
            }
            assert_int_equal(fogvol_sum_encoded(back, k, sb, &satb), FOGVOL_SUCCESS);
            assert_int_equal(fogvol_sum_encoded(front, k, sf, &satf), FOGVOL_SUCCESS);
            /* each channel of one face is <= N-1 (alpha <= 1): k*(N-1) <= 2^(8-L)*(2^L-1) < 256 */
            assert_int_equal(satb, 0);
            assert_int_equal(satf, 0);
            /* the sums are exact: decode(sum) * N^3 equals the sum of the face integers */
            CHECK_NEAR(fogvol_decode(&e, sb) * n3, (double)vb, 0);
            CHECK_NEAR(fogvol_decode(&e, sf) * n3, (double)vf, 0);
            diff = fogvol_decode(&e, sb) - fogvol_decode(&e, sf);
            CHECK_NEAR(fogvol_decode_difference(&e, sb, sf), diff, 1e-12);
            err = fabs(diff - exact) * n3; /* in LSB */
            /* allow = k LSB (row 0: 1 per pair) or 2k LSB (dithered: 1 per face), plus the clamp
               excess of the rare faces above 1 - 1.5/N^3 (see face_bound) */
            CHECK_MSG(err <= allow + 1e-9, "L=%d k=%d dither=%d error %.6f LSB > %.3f", L, k, dither, err, allow);
            if (err / allow > ratio) ratio = err / allow;
            if (!dither) {
                if (err / k > worst0) worst0 = err / k;
            } else {
                if (err / k > worstd) worstd = err / k;
                meand += (diff - exact) * n3 / (2 * k);
                cnt_d++;
            }
        }
        print_message("sums L=%d: worst |error| per face pair: row 0 %.4f LSB, dithered %.4f LSB (bounds 1 and 2 "
                      "plus clamp excess; worst error/bound %.3f); mean dithered error per face %+.4f LSB\n",
                      L, worst0, worstd, ratio, meand / cnt_d);
    }

    /* decode_difference on arbitrary bytes == decode(a) - decode(b) == (dV)/N^3 computed here */
    for (L = 1; L <= 8; ++L) {
        fogvol_encoding e = make_enc(L);
        const int n = e.levels;
        const double n3 = (double)n * n * n;
        int i, c;
        for (i = 0; i < 2000; ++i) {
            unsigned char a[4], b[4];
            long long dv;
            for (c = 0; c < 4; ++c) {
                a[c] = (unsigned char)rng_int(&rng, 256);
                b[c] = (unsigned char)rng_int(&rng, 256);
            }
            dv = value_of(n, a) - value_of(n, b);
            CHECK_NEAR(fogvol_decode_difference(&e, a, b), (double)dv / n3, 1e-12);
            CHECK_NEAR(fogvol_decode_difference(&e, a, b), fogvol_decode(&e, a) - fogvol_decode(&e, b), 1e-12);
            CHECK_NEAR(fogvol_decode(&e, a), (double)value_of(n, a) / n3, 0);
        }
    }

    /* Past the limit. With every face at the top (R = G = B = N-1 for row 0 at d = 1, and R = N-1
       for any d >= 1 - 1/(2N)), the red sum is count*(N-1): exactly representable while
       count*(N-1) <= 255, i.e. count <= floor(255/(N-1)), and saturated beyond. That is
       max_faces + 1 faces for L >= 5 (9*31 = 279 > 255), while for L <= 4 the 2^(8-L) of the
       table is conservative (L=4: 17*15 = 255 still fits). */
    for (L = 1; L <= 8; ++L) {
        fogvol_encoding e = make_enc(L);
        const int n = e.levels, nok = 255 / (n - 1);
        const double n3 = (double)n * n * n;
        int count, i;
        if (L >= 5) {
            assert_int_equal(nok, e.max_faces);
        } else {
            assert_true(nok > e.max_faces);
        }
        for (count = e.max_faces; count <= nok + 3 && count <= MAX_SUM_FACES; ++count) {
            unsigned char s[4];
            long long v = 0;
            int sat = -1;
            for (i = 0; i < count; ++i) {
                double d = 1.0 - 0.5 / n * rng_unit(&rng); /* in (1 - 1/(2N), 1] */
                int row = (i % 3 == 0) ? 0 : rng_int(&rng, e.dither_steps);
                assert_int_equal(fogvol_encode_depth(&e, d, row, back + 4 * i), FOGVOL_SUCCESS);
                assert_int_equal(back[4 * i], n - 1);
                v += value_of(n, back + 4 * i);
            }
            assert_int_equal(fogvol_sum_encoded(back, count, s, &sat), FOGVOL_SUCCESS);
            CHECK_MSG(sat == (count * (n - 1) > 255), "L=%d count=%d sat=%d", L, count, sat);
            if (sat) {
                /* the red channel stuck at 255: the decode lost at least (count*(N-1) - 255) reds */
                assert_int_equal(s[0], 255);
                assert_true(fogvol_decode(&e, s) * n3 < (double)v);
            } else {
                CHECK_NEAR(fogvol_decode(&e, s) * n3, (double)v, 0);
            }
        }
    }

    /* Detection is exact saturation, not a face count: L = 4, 48 faces (3x max_faces) with
       d < 4/4096 (V <= 4: R = G = 0, B <= 4) sum to at most 192 per channel: exact. */
    {
        fogvol_encoding e = make_enc(4);
        unsigned char s[4];
        long long v = 0;
        double exact = 0;
        int i, sat = -1;
        for (i = 0; i < 48; ++i) {
            double d = 4.0 / 4096.0 * rng_unit(&rng);
            assert_int_equal(fogvol_encode_depth(&e, d, 0, back + 4 * i), FOGVOL_SUCCESS);
            v += value_of(16, back + 4 * i);
            exact += d;
        }
        assert_int_equal(fogvol_sum_encoded(back, 48, s, &sat), FOGVOL_SUCCESS);
        assert_int_equal(sat, 0);
        CHECK_NEAR(fogvol_decode(&e, s) * 4096.0, (double)v, 0);
        assert_true(fabs(fogvol_decode(&e, s) - exact) * 4096.0 <= 48 * 0.5 + 1e-9);
        assert_true(48 > e.max_faces);
    }

    /* argument checks */
    {
        unsigned char s[4] = {7, 7, 7, 7};
        int sat = 5;
        assert_int_equal(fogvol_sum_encoded(NULL, 0, s, &sat), FOGVOL_SUCCESS);
        assert_int_equal(s[0] + s[1] + s[2] + s[3], 0);
        assert_int_equal(sat, 0);
        assert_int_equal(fogvol_sum_encoded(NULL, 2, s, &sat), FOGVOL_ERROR_INVALID_ARGUMENT);
        assert_int_equal(fogvol_sum_encoded(back, -1, s, &sat), FOGVOL_ERROR_INVALID_ARGUMENT);
        assert_int_equal(fogvol_sum_encoded(back, 1, NULL, &sat), FOGVOL_ERROR_INVALID_ARGUMENT);
        assert_int_equal(fogvol_sum_encoded(back, 1, s, NULL), FOGVOL_SUCCESS);
    }
    (void)front;
}

/* ------------------------------------------------------------------------ */
/* 5. dither                                                                */
/* ------------------------------------------------------------------------ */

typedef struct dither_stats {
    double max_abs_bias, sum_bias, max_row0;
    long long points;
} dither_stats;

/* Checks one depth x = d*N^3 (in LSB) on every row; returns the row-averaged bias in LSB. */
static double check_depth_all_rows(const fogvol_encoding *e, double x, dither_stats *st, long long *prev_v)
{
    const int n = e->levels, dsteps = e->dither_steps;
    const double n3 = (double)n * n * n;
    const double d = x / n3;
    long long sum = 0, h = (long long)floor((x + 1.0) / n); /* rg texel at T1 = x + 1 */
    int r;
    double avg, bias;
    for (r = 0; r < dsteps; ++r) {
        unsigned char b[4];
        long long v, want;
        int k = row_k(r, dsteps);
        if (fogvol_encode_depth(e, d, r, b) != FOGVOL_SUCCESS) fail();
        v = value_of(n, b);
        want = model_value(x, k, dsteps);
        if (v != want || b[0] >= n || b[1] >= n || b[2] >= n || b[3] > 1) {
            print_error("L=%d x=%.9f row %d: bytes (%d,%d,%d,%d) V=%lld, model %lld\n", e->bits, x, r, b[0], b[1],
                        b[2], b[3], v, want);
            fail();
        }
        /* bytes from V and the rg texel: (R,G) are the digits of h; A = 1 exactly when V < h*N */
        if (h / n != b[0] || h % n != b[1] || (v < h * n) != (b[3] == 1) || v < h * n - 1 || v > h * n + n - 1) {
            print_error("L=%d x=%.9f row %d: bytes (%d,%d,%d,%d) inconsistent with rg texel h=%lld\n", e->bits, x,
                        r, b[0], b[1], b[2], b[3], h);
            fail();
        }
        if (prev_v) {
            if (v < prev_v[r]) {
                print_error("L=%d x=%.9f row %d: V=%lld below the previous %lld (not monotone)\n", e->bits, x, r,
                            v, prev_v[r]);
                fail();
            }
            prev_v[r] = v;
        }
        if (r == 0) {
            double e0 = fabs((double)v - x);
            if (!(e0 <= 0.5)) {
                print_error("L=%d x=%.9f row 0: V=%lld, error %.6f LSB > 0.5\n", e->bits, x, v, e0);
                fail();
            }
            if (e0 > st->max_row0) st->max_row0 = e0;
        }
        sum += v;
    }
    avg = (double)sum / dsteps;
    bias = avg - x;
    if (!(fabs(bias) <= 0.1) || !(fabs(bias) < 1.0 / dsteps + 1e-12)) {
        print_error("L=%d x=%.9f: rows average %.6f, bias %.6f LSB (limit 0.1 and 1/D)\n", e->bits, x, avg, bias);
        fail();
    }
    if (fabs(bias) > st->max_abs_bias) st->max_abs_bias = fabs(bias);
    st->sum_bias += bias;
    st->points++;
    return bias;
}

static void test_dither(void **state)
{
    static const int bits_list[3] = {2, 4, 5};
    /* FOGVOL_TEST_SUBSET (make test sets it for the run under valgrind, where L = 5's 20 million
       encodings take minutes; the plain, sanitizer and C++ builds run all three): L = 2 and 4, which
       run the same lines of fogvol.h (gcov) */
    const char *subset = getenv("FOGVOL_TEST_SUBSET");
    int li, nl = subset && *subset ? 2 : 3;
    (void)state;
    if (nl < 3) print_message("# FOGVOL_TEST_SUBSET: the dither at L = 2 and 4 (the other builds add L = 5)\n");
    for (li = 0; li < nl; ++li) {
        const int L = bits_list[li];
        fogvol_encoding e = make_enc(L);
        const int n = e.levels, dsteps = e.dither_steps;
        const long long n3 = (long long)n * n * n;
        /* 19 sub-steps per LSB (not a power of two, so the sub-texel phase x*D mod 1 takes 19
           different values instead of always 0), across [0, N^3 - 2] LSB: every blue wrap */
        const int sub = 19;
        long long j, jmax = (n3 - 2) * sub;
        long long prev[32];
        dither_stats sweep, wrap, rnd;
        rng_t rng;
        int r;
        memset(&sweep, 0, sizeof sweep);
        memset(&wrap, 0, sizeof wrap);
        memset(&rnd, 0, sizeof rnd);
        for (r = 0; r < 32; ++r) prev[r] = -1;
        for (j = 0; j <= jmax; ++j) check_depth_all_rows(&e, (double)j / sub, &sweep, prev);

        /* around every wrap of the blue ramp: x = m*N + delta, delta in [-1, 1], both off-grid
           (1/96 off the 1/32 grid) and on exact binary fractions (ties of row 0 included) */
        {
            long long m;
            for (m = 1; m < n3 / n; ++m) {
                int i;
                for (i = 0; i < 64; ++i) check_depth_all_rows(&e, (double)(m * n) - 1.0 + i / 32.0 + 1.0 / 96.0, &wrap, NULL);
                for (i = 0; i <= 8; ++i) check_depth_all_rows(&e, (double)(m * n) - 1.0 + i / 4.0, &wrap, NULL);
            }
        }
        /* row 0 rounds ties up: x = m*N - 0.5 -> m*N (floor(x + 1/2)) */
        {
            unsigned char b[4];
            assert_int_equal(fogvol_encode_depth(&e, ((double)(5 * n) - 0.5) / (double)n3, 0, b), FOGVOL_SUCCESS);
            assert_int_equal(value_of(n, b), 5 * n);
        }
        /* uniformly random depths: the expected bias (phase of x*D uniform) */
        rng.s = UINT64_C(0x1234567887654321) + (uint64_t)L;
        for (j = 0; j < 20000; ++j) check_depth_all_rows(&e, rng_unit(&rng) * (double)(n3 - 2), &rnd, NULL);
        /* the mean bias of the rows' average is at most half a blue texel (0.5/D) in size */
        CHECK_MSG(fabs(rnd.sum_bias / rnd.points) <= 0.5 / dsteps + 0.002, "L=%d mean bias %.5f", L,
                  rnd.sum_bias / rnd.points);

        print_message("dither L=%d (D=%d): sweep %lld depths (1/%d LSB steps): rows-average |bias| max %.5f LSB, "
                      "mean %+.5f LSB; row 0 max |error| %.5f LSB\n",
                      L, dsteps, sweep.points, sub, sweep.max_abs_bias, sweep.sum_bias / sweep.points, sweep.max_row0);
        print_message("dither L=%d (D=%d): blue wraps %lld depths: |bias| max %.5f LSB, mean %+.5f LSB; row 0 max "
                      "|error| %.5f LSB\n",
                      L, dsteps, wrap.points, wrap.max_abs_bias, wrap.sum_bias / wrap.points, wrap.max_row0);
        print_message("dither L=%d (D=%d): %lld random depths: |bias| max %.5f LSB, mean %+.5f LSB "
                      "(-0.5/D = %+.5f)\n",
                      L, dsteps, rnd.points, rnd.max_abs_bias, rnd.sum_bias / rnd.points, -0.5 / dsteps);
        /* row 0 error reaches 0.5 exactly at the ties of the wrap set */
        CHECK_NEAR(wrap.max_row0, 0.5, 0);
    }
}

/* ------------------------------------------------------------------------ */
/* 6. textures                                                              */
/* ------------------------------------------------------------------------ */

typedef fogvol_result (*tex_fn)(const fogvol_encoding *, unsigned char *, size_t, fogvol_image *);

/* A buffer one byte short (plus a canary zone) must be refused and left untouched. */
static void check_too_small(const fogvol_encoding *e, tex_fn fn, size_t size)
{
    unsigned char *buf = (unsigned char *)malloc(size + 64);
    unsigned char *ref = (unsigned char *)malloc(size + 64);
    fogvol_image info;
    assert_non_null(buf);
    assert_non_null(ref);
    memset(buf, 0xA5, size + 64);
    memset(ref, 0xA5, size + 64);
    memset(&info, 0, sizeof info);
    assert_int_equal(fn(e, buf, size - 1, &info), FOGVOL_ERROR_BUFFER_TOO_SMALL);
    assert_memory_equal(buf, ref, size + 64);
    assert_int_equal(info.size, size); /* the size is still reported */
    assert_int_equal(fn(e, buf, 0, &info), FOGVOL_ERROR_BUFFER_TOO_SMALL);
    assert_memory_equal(buf, ref, size + 64);
    assert_int_equal(fn(e, buf, size, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    free(buf);
    free(ref);
}

static void test_textures(void **state)
{
    int L;
    (void)state;
    for (L = 1; L <= 8; ++L) {
        fogvol_encoding e = make_enc(L), bad = make_enc(L);
        const int n = e.levels, dsteps = e.dither_steps;
        fogvol_image info;
        unsigned char *px;
        int x, y, r;

        /* ---- rg ramp: N x N, texel (x, y) = (x, y, 0, 0) ---- */
        memset(&info, 0, sizeof info);
        assert_int_equal(fogvol_make_rg_ramp(&e, NULL, 0, &info), FOGVOL_SUCCESS);
        assert_int_equal(info.width, n);
        assert_int_equal(info.height, n);
        assert_int_equal(info.size, (size_t)n * n * 4);
        check_too_small(&e, fogvol_make_rg_ramp, info.size);
        px = (unsigned char *)malloc(info.size);
        assert_non_null(px);
        assert_int_equal(fogvol_make_rg_ramp(&e, px, info.size, &info), FOGVOL_SUCCESS);
        for (y = 0; y < n; ++y)
            for (x = 0; x < n; ++x) {
                const unsigned char *p = px + ((size_t)y * n + x) * 4;
                assert_int_equal(p[0], x);
                assert_int_equal(p[1], y);
                assert_int_equal(p[2], 0);
                assert_int_equal(p[3], 0);
            }
        free(px);

        /* ---- blue ramp: (N*D) x D ---- */
        memset(&info, 0, sizeof info);
        assert_int_equal(fogvol_make_blue_ramp(&e, NULL, 0, &info), FOGVOL_SUCCESS);
        assert_int_equal(info.width, n * dsteps);
        assert_int_equal(info.height, dsteps);
        assert_int_equal(info.size, (size_t)n * dsteps * dsteps * 4);
        check_too_small(&e, fogvol_make_blue_ramp, info.size);
        px = (unsigned char *)malloc(info.size);
        assert_non_null(px);
        assert_int_equal(fogvol_make_blue_ramp(&e, px, info.size, &info), FOGVOL_SUCCESS);
        CHECK_NEAR(fogvol_dither_threshold(&e, 0), 0.5, 0);
        for (r = 0; r < dsteps; ++r) {
            /* threshold of row r: ((r + D/2) mod D)/D; texel x stands for the blue position x/D in
               the period of T1 = V + 1, so its digit is floor(x/D + threshold) - 1 (borrow: -1) */
            const double th = (double)row_k(r, dsteps) / dsteps;
            int prev = -2;
            CHECK_NEAR(fogvol_dither_threshold(&e, r), th, 0);
            for (x = 0; x < n * dsteps; ++x) {
                const unsigned char *p = px + ((size_t)r * n * dsteps + x) * 4;
                int q = (int)floor((double)x / dsteps + th) - 1;
                int got = p[2] - (p[3] ? n : 0);
                assert_true(p[2] <= n - 1);
                assert_true(p[3] <= 1);
                assert_int_equal(p[0], 0);
                assert_int_equal(p[1], 0);
                if (got != q) {
                    print_error("L=%d blue ramp row %d x %d: (B,A) = (%d,%d), expected digit %d\n", L, r, x, p[2],
                                p[3], q);
                    fail();
                }
                assert_true(got >= prev); /* a staircase */
                prev = got;
                if (r == 0) {
                    /* row 0 = round to nearest of x/D - 1: texels x < D/2 borrow, the step
                       from digit j-1 to j is at x = j*D - D/2 */
                    assert_int_equal(got, (2 * x + dsteps) / (2 * dsteps) - 1);
                    assert_int_equal(p[3], x < dsteps / 2 ? 1 : 0);
                }
            }
        }
        CHECK_NEAR(fogvol_dither_threshold(&e, -1), 0.0, 0);
        CHECK_NEAR(fogvol_dither_threshold(&e, dsteps), 0.0, 0);
        free(px);

        /* ---- dither index: 8 x 8, red = row; every row 64/D times ---- */
        memset(&info, 0, sizeof info);
        assert_int_equal(fogvol_make_dither_index(&e, NULL, 0, &info), FOGVOL_SUCCESS);
        assert_int_equal(info.width, 8);
        assert_int_equal(info.height, 8);
        assert_int_equal(info.size, 256);
        check_too_small(&e, fogvol_make_dither_index, info.size);
        px = (unsigned char *)malloc(info.size);
        assert_non_null(px);
        assert_int_equal(fogvol_make_dither_index(&e, px, info.size, &info), FOGVOL_SUCCESS);
        {
            int hist[32];
            memset(hist, 0, sizeof hist);
            for (y = 0; y < 8; ++y)
                for (x = 0; x < 8; ++x) {
                    int row = px[(y * 8 + x) * 4];
                    assert_true(row < dsteps);
                    hist[row]++;
                }
            for (r = 0; r < dsteps; ++r) assert_int_equal(hist[r], 64 / dsteps);
            /* the classic 8x8 Bayer matrix (as published, row y = 0 first), scaled to the D
               thresholds: pixel (x, y) gets threshold k = floor(M*D/64), i.e. row (k + D/2) mod D */
            {
                static const int bayer[8][8] = {{0, 32, 8, 40, 2, 34, 10, 42},  {48, 16, 56, 24, 50, 18, 58, 26},
                                                {12, 44, 4, 36, 14, 46, 6, 38}, {60, 28, 52, 20, 62, 30, 54, 22},
                                                {3, 35, 11, 43, 1, 33, 9, 41},  {51, 19, 59, 27, 49, 17, 57, 25},
                                                {15, 47, 7, 39, 13, 45, 5, 37}, {63, 31, 55, 23, 61, 29, 53, 21}};
                for (y = 0; y < 8; ++y)
                    for (x = 0; x < 8; ++x) {
                        const int k = bayer[y][x] * dsteps / 64;
                        assert_int_equal(px[(y * 8 + x) * 4], (k + dsteps / 2) % dsteps);
                        assert_int_equal(row_k(px[(y * 8 + x) * 4], dsteps), k);
                    }
            }
            /* ordered dither: every aligned 2x2 block holds the thresholds k0, k0 + D/4,
               k0 + D/2, k0 + 3D/4 (one in each quarter), so any 2x2 area averages out */
            for (y = 0; y < 8; y += 2)
                for (x = 0; x < 8; x += 2) {
                    int ks[4], i, j, t;
                    ks[0] = row_k(px[(y * 8 + x) * 4], dsteps);
                    ks[1] = row_k(px[(y * 8 + x + 1) * 4], dsteps);
                    ks[2] = row_k(px[((y + 1) * 8 + x) * 4], dsteps);
                    ks[3] = row_k(px[((y + 1) * 8 + x + 1) * 4], dsteps);
                    for (i = 0; i < 4; ++i)
                        for (j = i + 1; j < 4; ++j)
                            if (ks[j] < ks[i]) {
                                t = ks[i];
                                ks[i] = ks[j];
                                ks[j] = t;
                            }
                    for (i = 1; i < 4; ++i) assert_int_equal(ks[i] - ks[0], i * dsteps / 4);
                }
        }
        free(px);

        /* invalid encodings */
        bad.dither_steps = 7;
        assert_int_equal(fogvol_make_rg_ramp(&bad, NULL, 0, &info), FOGVOL_ERROR_INVALID_ARGUMENT);
        assert_int_equal(fogvol_make_blue_ramp(&bad, NULL, 0, &info), FOGVOL_ERROR_INVALID_ARGUMENT);
        assert_int_equal(fogvol_make_dither_index(&bad, NULL, 0, &info), FOGVOL_ERROR_INVALID_ARGUMENT);
        assert_int_equal(fogvol_make_rg_ramp(NULL, NULL, 0, &info), FOGVOL_ERROR_INVALID_ARGUMENT);
    }
}

/* ------------------------------------------------------------------------ */
/* 7. colour ramps                                                          */
/* ------------------------------------------------------------------------ */

static int round255(double v)
{
    if (v < 0) v = 0;
    if (v > 1) v = 1;
    return (int)floor(v * 255.0 + 0.5);
}

static void test_color_ramps(void **state)
{
    fogvol_ramp_desc rd;
    fogvol_image info;
    unsigned char px[4096 * 4 + 16];
    float tmax = -1;
    int i;
    (void)state;

    /* extinction: width 256 (default), density 0.7, colour (0.2,0.4,0.6), auto max = 7/0.7 = 10 */
    memset(&rd, 0, sizeof rd);
    rd.model = FOGVOL_RAMP_EXTINCTION;
    rd.color[0] = 0.2f;
    rd.color[1] = 0.4f;
    rd.color[2] = 0.6f;
    rd.density = 0.7f;
    memset(&info, 0, sizeof info);
    assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, &tmax), FOGVOL_SUCCESS);
    assert_int_equal(info.width, 256);
    assert_int_equal(info.height, 1);
    assert_int_equal(info.size, 1024);
    CHECK_NEAR(tmax, 10.0, 1e-5);
    memset(px, 0xA5, sizeof px);
    assert_int_equal(fogvol_make_color_ramp(&rd, px, 1023, &info, NULL), FOGVOL_ERROR_BUFFER_TOO_SMALL);
    for (i = 0; i < (int)sizeof px; ++i) assert_int_equal(px[i], 0xA5);
    assert_int_equal(fogvol_make_color_ramp(&rd, px, 1024, &info, &tmax), FOGVOL_SUCCESS);
    for (i = 1024; i < (int)sizeof px; ++i) assert_int_equal(px[i], 0xA5);
    for (i = 0; i < 256; ++i) {
        double t = 10.0 * i / 255.0;
        int want = round255(1.0 - exp(-0.7 * t));
        assert_int_equal(px[4 * i + 0], 51);  /* 0.2*255 */
        assert_int_equal(px[4 * i + 1], 102); /* 0.4*255 */
        assert_int_equal(px[4 * i + 2], 153); /* 0.6*255 */
        CHECK_MSG(abs(px[4 * i + 3] - want) <= 1, "extinction texel %d alpha %d, want %d", i, px[4 * i + 3], want);
    }
    assert_int_equal(px[3], 0);
    assert_int_equal(px[4 * 255 + 3], 255); /* 1 - e^-7 = 0.99909 -> 254.77 -> 255 */

    /* explicit max thickness 20 over 5 texels: t = 0,5,10,15,20 */
    rd.max_thickness = 20.0f;
    rd.width = 5;
    assert_int_equal(fogvol_make_color_ramp(&rd, px, sizeof px, &info, &tmax), FOGVOL_SUCCESS);
    CHECK_NEAR(tmax, 20.0, 0);
    for (i = 0; i < 5; ++i) assert_int_equal(px[4 * i + 3], round255(1.0 - exp(-0.7 * 5.0 * i)));

    /* linear: density 0.25, auto max = 1/0.25 = 4, width 5: t = 0..4 -> a = 0, .25, .5, .75, 1
       -> bytes 0, 64 (63.75), 128 (127.5 rounds up), 191 (191.25), 255 */
    memset(&rd, 0, sizeof rd);
    rd.model = FOGVOL_RAMP_LINEAR;
    rd.color[0] = 1.0f;
    rd.color[1] = 0.0f;
    rd.color[2] = 0.5f;
    rd.density = 0.25f;
    rd.width = 5;
    assert_int_equal(fogvol_make_color_ramp(&rd, px, sizeof px, &info, &tmax), FOGVOL_SUCCESS);
    CHECK_NEAR(tmax, 4.0, 0);
    {
        static const int want[5] = {0, 64, 128, 191, 255};
        for (i = 0; i < 5; ++i) {
            assert_int_equal(px[4 * i + 0], 255);
            assert_int_equal(px[4 * i + 1], 0);
            assert_int_equal(px[4 * i + 2], 128); /* 127.5 -> 128 */
            assert_int_equal(px[4 * i + 3], want[i]);
        }
    }
    /* linear clamps at 1: max 8 over 9 texels, t = 0..8 */
    rd.max_thickness = 8.0f;
    rd.width = 9;
    assert_int_equal(fogvol_make_color_ramp(&rd, px, sizeof px, &info, NULL), FOGVOL_SUCCESS);
    {
        static const int want[9] = {0, 64, 128, 191, 255, 255, 255, 255, 255};
        for (i = 0; i < 9; ++i) assert_int_equal(px[4 * i + 3], want[i]);
    }

    /* gradient, keys out of order: t=4 (1,0,0,1), t=0 (0,0,0,0), t=2 (0,1,0,0.5); auto max = 4,
       width 5 -> t = 0,1,2,3,4:
       t0 (0,0,0,0); t1 halfway key0..key2 = (0,.5,0,.25) -> (0,128,0,64); t2 (0,255,0,128);
       t3 halfway key2..key4 = (.5,.5,0,.75) -> (128,128,0,191); t4 (255,0,0,255) */
    {
        fogvol_color_key keys[3];
        static const unsigned char want[5][4] = {
            {0, 0, 0, 0}, {0, 128, 0, 64}, {0, 255, 0, 128}, {128, 128, 0, 191}, {255, 0, 0, 255}};
        static const unsigned char w2[4][4] = {{0, 0, 255, 0}, {0, 0, 255, 0}, {0, 128, 128, 64}, {0, 255, 0, 128}};
        memset(keys, 0, sizeof keys);
        keys[0].thickness = 4.0f;
        keys[0].rgba[0] = 1.0f;
        keys[0].rgba[3] = 1.0f;
        keys[1].thickness = 0.0f;
        keys[2].thickness = 2.0f;
        keys[2].rgba[1] = 1.0f;
        keys[2].rgba[3] = 0.5f;
        memset(&rd, 0, sizeof rd);
        rd.model = FOGVOL_RAMP_GRADIENT;
        rd.keys = keys;
        rd.key_count = 3;
        rd.width = 5;
        assert_int_equal(fogvol_make_color_ramp(&rd, px, sizeof px, &info, &tmax), FOGVOL_SUCCESS);
        CHECK_NEAR(tmax, 4.0, 0);
        assert_memory_equal(px, want, sizeof want);
        /* beyond the last key it holds the last key: max 6, width 4 -> t = 0, 2, 4, 6 */
        rd.max_thickness = 6.0f;
        rd.width = 4;
        assert_int_equal(fogvol_make_color_ramp(&rd, px, sizeof px, &info, &tmax), FOGVOL_SUCCESS);
        assert_memory_equal(px + 0, want[0], 4);
        assert_memory_equal(px + 4, want[2], 4);
        assert_memory_equal(px + 8, want[4], 4);
        assert_memory_equal(px + 12, want[4], 4);
        /* below the first key it holds the first key: keys at 1 and 3 only, max 3, width 4 ->
           t = 0 (key t=1 colour), 1, 2 (halfway), 3 */
        keys[1].thickness = 1.0f;
        keys[1].rgba[2] = 1.0f; /* (0,0,1,0) at t = 1 */
        keys[2].thickness = 3.0f; /* (0,1,0,0.5) at t = 3 */
        rd.keys = keys + 1;       /* the two keys at t = 1 and t = 3 */
        rd.key_count = 2;
        rd.max_thickness = 3.0f;
        assert_int_equal(fogvol_make_color_ramp(&rd, px, sizeof px, &info, NULL), FOGVOL_SUCCESS);
        assert_memory_equal(px, w2, sizeof w2);
        /* a single key: constant */
        rd.key_count = 1;
        rd.max_thickness = 0;
        assert_int_equal(fogvol_make_color_ramp(&rd, px, sizeof px, &info, &tmax), FOGVOL_SUCCESS);
        CHECK_NEAR(tmax, 1.0, 0);
        for (i = 0; i < 4; ++i) assert_memory_equal(px + 4 * i, w2[0], 4);
        /* invalid gradients */
        rd.key_count = 0;
        assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
        rd.key_count = 2;
        rd.keys = NULL;
        assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
        rd.keys = keys;
        keys[0].rgba[1] = (float)NAN;
        assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
        keys[0].rgba[1] = 0;
        keys[0].thickness = -1.0f;
        assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    }

    /* invalid descs */
    memset(&rd, 0, sizeof rd);
    rd.model = FOGVOL_RAMP_EXTINCTION;
    rd.color[0] = rd.color[1] = rd.color[2] = 0.5f;
    rd.density = 1.0f;
    assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, NULL), FOGVOL_SUCCESS);
    rd.density = 0.0f;
    assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    rd.density = -1.0f;
    assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    rd.density = (float)NAN;
    assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    rd.model = FOGVOL_RAMP_LINEAR;
    rd.density = 0.0f;
    assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    rd.density = 1.0f;
    rd.color[1] = (float)NAN;
    assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    rd.color[1] = (float)INFINITY;
    assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    rd.color[1] = 0.5f;
    rd.width = 1;
    assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    rd.width = 4097;
    assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    rd.width = -5;
    assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    rd.width = 4096;
    assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, NULL), FOGVOL_SUCCESS);
    assert_int_equal(info.size, 4096 * 4);
    rd.width = 2;
    assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, NULL), FOGVOL_SUCCESS);
    rd.max_thickness = -1.0f;
    assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    rd.max_thickness = (float)NAN;
    assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    rd.max_thickness = 0;
    rd.model = (fogvol_ramp_model)7;
    assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    rd.model = FOGVOL_RAMP_LINEAR;
    rd.blend = (fogvol_blend)5;
    assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    rd.blend = FOGVOL_BLEND_LIGHT;
    assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, &info, NULL), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_make_color_ramp(NULL, NULL, 0, &info, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_make_color_ramp(&rd, NULL, 0, NULL, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
}

/* With the automatic max thickness an extinction ramp covers 0..7/density, so its alpha curve is
   1 - exp(-7 i/(w-1)) whatever the density. Checked over a wide range of densities, down to
   2e-38 (a normal float whose 7/density = 3.5e38 overflows float). A library may refuse a density
   whose range it cannot represent (INVALID_ARGUMENT), but if it accepts it the resolved max
   thickness must be finite and the texels right. */
static void test_color_ramp_auto_range(void **state)
{
    static const float dens[] = {1e-3f, 0.05f, 1.0f, 123.0f, 1e6f, 2e-38f};
    fogvol_ramp_desc rd;
    fogvol_image info;
    unsigned char px[64 * 4];
    float tmax;
    int di, i;
    (void)state;
    memset(&rd, 0, sizeof rd);
    rd.model = FOGVOL_RAMP_EXTINCTION;
    rd.color[0] = rd.color[1] = rd.color[2] = 1.0f;
    rd.width = 64;
    for (di = 0; di < (int)(sizeof dens / sizeof dens[0]); ++di) {
        fogvol_result res;
        rd.density = dens[di];
        tmax = -1;
        res = fogvol_make_color_ramp(&rd, px, sizeof px, &info, &tmax);
        if (res == FOGVOL_ERROR_INVALID_ARGUMENT) continue;
        assert_int_equal(res, FOGVOL_SUCCESS);
        CHECK_MSG(isfinite(tmax) && tmax > 0, "density %g: resolved max_thickness %g", (double)dens[di],
                  (double)tmax);
        CHECK_NEAR(tmax * (double)dens[di], 7.0, 1e-5);
        for (i = 0; i < 64; ++i) {
            int want = round255(1.0 - exp(-7.0 * i / 63.0));
            CHECK_MSG(abs(px[4 * i + 3] - want) <= 1, "density %g texel %d alpha %d, want %d", (double)dens[di], i,
                      px[4 * i + 3], want);
        }
    }
    /* the linear model likewise covers 0..1/density: alpha = i/(w-1); 1/2e-39 overflows too */
    rd.model = FOGVOL_RAMP_LINEAR;
    for (di = 0; di < 2; ++di) {
        fogvol_result res;
        rd.density = di == 0 ? 0.5f : 2e-39f;
        tmax = -1;
        res = fogvol_make_color_ramp(&rd, px, sizeof px, &info, &tmax);
        if (res == FOGVOL_ERROR_INVALID_ARGUMENT) continue;
        assert_int_equal(res, FOGVOL_SUCCESS);
        CHECK_MSG(isfinite(tmax) && tmax > 0, "linear density %g: resolved max_thickness %g", (double)rd.density,
                  (double)tmax);
        for (i = 0; i < 64; ++i) {
            int want = round255(i / 63.0);
            CHECK_MSG(abs(px[4 * i + 3] - want) <= 1, "linear density %g texel %d alpha %d, want %d",
                      (double)rd.density, i, px[4 * i + 3], want);
        }
    }
}

/* ------------------------------------------------------------------------ */
/* 8. mesh validation                                                       */
/* ------------------------------------------------------------------------ */

/* 2x2x2 cube [-1,1]^3, vertex i = (bit0 ? 1 : -1, bit1 ? 1 : -1, bit2 ? 1 : -1). */
static const float cube_v[8 * 3] = {-1, -1, -1, 1, -1, -1, -1, 1, -1, 1, 1, -1,
                                    -1, -1, 1,  1, -1, 1,  -1, 1, 1,  1, 1, 1};
/* Faces as quads (a,b,c,d) -> triangles (a,b,c), (a,c,d); (b-a) x (c-a) points outward:
   -x: 0,4,6,2 (z x (y+z) = -x)   +x: 1,3,7,5 (y x (y+z) = +x)
   -y: 0,1,5,4 (x x (x+z) = -y)   +y: 2,6,7,3 (z x (z+x) = +y)
   -z: 0,2,3,1 (y x (y+x) = -z)   +z: 4,5,7,6 (x x (x+y) = +z) */
static const uint32_t cube_i[36] = {0, 4, 6, 0, 6, 2, /* -x */
                                    1, 3, 7, 1, 7, 5, /* +x */
                                    0, 1, 5, 0, 5, 4, /* -y */
                                    2, 6, 7, 2, 7, 3, /* +y */
                                    0, 2, 3, 0, 3, 1, /* -z */
                                    4, 5, 7, 4, 7, 6 /* +z */};

static fogvol_mesh_desc mesh_desc(const float *v, int nv, const uint32_t *idx, int ni)
{
    fogvol_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.positions = v;
    d.vertex_count = nv;
    d.indices = idx;
    d.index_count = ni;
    return d;
}

static fogvol_result validate(const float *v, int nv, const uint32_t *idx, int ni, fogvol_mesh_report *rep)
{
    fogvol_mesh_desc d = mesh_desc(v, nv, idx, ni);
    return fogvol_validate_mesh(&d, NULL, rep);
}

static void flip(uint32_t *tri)
{
    uint32_t t = tri[1];
    tri[1] = tri[2];
    tri[2] = t;
}

static void test_mesh_cube(void **state)
{
    fogvol_mesh_report rep;
    uint32_t idx[48];
    int i;
    (void)state;

    /* the closed, outward cube: volume 2^3 = 8 */
    assert_int_equal(validate(cube_v, 8, cube_i, 36, &rep), FOGVOL_SUCCESS);
    assert_int_equal(rep.vertices, 8);
    assert_int_equal(rep.triangles, 12);
    assert_int_equal(rep.open_edges, 0);
    assert_int_equal(rep.nonmanifold_edges, 0);
    assert_int_equal(rep.inconsistent_edges, 0);
    assert_int_equal(rep.flipped_faces, 0);
    assert_int_equal(rep.degenerate_triangles, 0);
    assert_int_equal(rep.nonfinite_vertices, 0);
    assert_int_equal(rep.out_of_range_indices, 0);
    assert_int_equal(rep.components, 1);
    CHECK_NEAR(rep.volume, 8.0, 1e-12);
    assert_true(rep.closed);
    assert_true(rep.consistent);
    assert_false(rep.inverted);
    assert_true(rep.valid);

    /* the +z face (2 triangles) missing: its 4 border edges lose a user -> 4 open edges
       (its diagonal 4-7 disappears with it) */
    assert_int_equal(validate(cube_v, 8, cube_i, 30, &rep), FOGVOL_ERROR_INVALID_MESH);
    assert_int_equal(rep.open_edges, 4);
    assert_int_equal(rep.nonmanifold_edges, 0);
    assert_false(rep.closed);
    assert_false(rep.valid);
    /* one triangle missing: 3 open edges */
    assert_int_equal(validate(cube_v, 8, cube_i + 3, 33, &rep), FOGVOL_ERROR_INVALID_MESH);
    assert_int_equal(rep.open_edges, 3);

    /* one triangle flipped: its 3 edges run the same way as the neighbours' */
    memcpy(idx, cube_i, sizeof cube_i);
    flip(idx + 3 * 7);
    assert_int_equal(validate(cube_v, 8, idx, 36, &rep), FOGVOL_ERROR_INVALID_MESH);
    assert_int_equal(rep.flipped_faces, 1);
    assert_int_equal(rep.inconsistent_edges, 3);
    assert_int_equal(rep.open_edges, 0);
    assert_true(rep.closed);
    assert_false(rep.consistent);
    assert_false(rep.valid);

    /* a whole face (both triangles of -y) flipped: the shared diagonal agrees, the 4 border
       edges do not */
    memcpy(idx, cube_i, sizeof cube_i);
    flip(idx + 3 * 4);
    flip(idx + 3 * 5);
    assert_int_equal(validate(cube_v, 8, idx, 36, &rep), FOGVOL_ERROR_INVALID_MESH);
    assert_int_equal(rep.flipped_faces, 2);
    assert_int_equal(rep.inconsistent_edges, 4);
    assert_false(rep.valid);

    /* wound inward everywhere: closed, consistent, inverted, volume -8 */
    memcpy(idx, cube_i, sizeof cube_i);
    for (i = 0; i < 12; ++i) flip(idx + 3 * i);
    assert_int_equal(validate(cube_v, 8, idx, 36, &rep), FOGVOL_ERROR_INVALID_MESH);
    assert_true(rep.closed);
    assert_true(rep.consistent);
    assert_true(rep.inverted);
    assert_int_equal(rep.flipped_faces, 0);
    assert_int_equal(rep.inconsistent_edges, 0);
    CHECK_NEAR(rep.volume, -8.0, 1e-12);
    assert_false(rep.valid);

    /* a NaN vertex; then an infinite one */
    {
        float v[24];
        memcpy(v, cube_v, sizeof v);
        v[3 * 5 + 1] = (float)NAN;
        assert_int_equal(validate(v, 8, cube_i, 36, &rep), FOGVOL_ERROR_INVALID_MESH);
        assert_int_equal(rep.nonfinite_vertices, 1);
        assert_false(rep.valid);
        v[3 * 5 + 1] = 1.0f;
        v[3 * 2 + 2] = (float)-INFINITY;
        assert_int_equal(validate(v, 8, cube_i, 36, &rep), FOGVOL_ERROR_INVALID_MESH);
        assert_int_equal(rep.nonfinite_vertices, 1);
    }

    /* an index past the end, with the positions in a heap block of exactly 8 vertices (ASan
       reports any read beyond): 8 and 0xffffffff */
    {
        float *v = (float *)malloc(sizeof cube_v);
        assert_non_null(v);
        memcpy(v, cube_v, sizeof cube_v);
        memcpy(idx, cube_i, sizeof cube_i);
        idx[13] = 8;
        assert_int_equal(validate(v, 8, idx, 36, &rep), FOGVOL_ERROR_INVALID_MESH);
        assert_int_equal(rep.out_of_range_indices, 1);
        assert_false(rep.valid);
        idx[13] = 0xffffffffu;
        idx[30] = 1000000u;
        assert_int_equal(validate(v, 8, idx, 36, &rep), FOGVOL_ERROR_INVALID_MESH);
        assert_int_equal(rep.out_of_range_indices, 2);
        /* and the index array itself read within its count: a 36-index heap block */
        {
            uint32_t *ib = (uint32_t *)malloc(sizeof cube_i);
            assert_non_null(ib);
            memcpy(ib, cube_i, sizeof cube_i);
            assert_int_equal(validate(v, 8, ib, 36, &rep), FOGVOL_SUCCESS);
            free(ib);
        }
        free(v);
    }

    /* a repeated-index triangle added to the closed cube: one degenerate triangle, no edges */
    memcpy(idx, cube_i, sizeof cube_i);
    idx[36] = 0;
    idx[37] = 0;
    idx[38] = 1;
    validate(cube_v, 8, idx, 39, &rep);
    assert_int_equal(rep.triangles, 13);
    assert_int_equal(rep.degenerate_triangles, 1);
    assert_int_equal(rep.open_edges, 0);
    assert_int_equal(rep.nonmanifold_edges, 0);
    CHECK_NEAR(rep.volume, 8.0, 1e-12);
    /* every position of the repeated index: (0,1,0), (2,5,5) and (3,3,3) */
    idx[36] = 0;
    idx[37] = 1;
    idx[38] = 0;
    idx[39] = 2;
    idx[40] = 5;
    idx[41] = 5;
    idx[42] = 3;
    idx[43] = 3;
    idx[44] = 3;
    validate(cube_v, 8, idx, 45, &rep);
    assert_int_equal(rep.triangles, 15);
    assert_int_equal(rep.degenerate_triangles, 3);
    assert_int_equal(rep.open_edges, 0);
    assert_int_equal(rep.nonmanifold_edges, 0);

    /* a zero-area sliver with distinct indices: vertex 8 = midpoint of edge 0-1, triangle
       (0,8,1): degenerate; its edges 0-8 and 8-1 are open, and edge 1-0 now has 3 users */
    {
        float v[27];
        memcpy(v, cube_v, sizeof cube_v);
        v[24] = 0.0f;
        v[25] = -1.0f;
        v[26] = -1.0f;
        memcpy(idx, cube_i, sizeof cube_i);
        idx[36] = 0;
        idx[37] = 8;
        idx[38] = 1;
        assert_int_equal(validate(v, 9, idx, 39, &rep), FOGVOL_ERROR_INVALID_MESH);
        assert_int_equal(rep.degenerate_triangles, 1);
        assert_int_equal(rep.open_edges, 2);
        assert_int_equal(rep.nonmanifold_edges, 1);
    }

    /* argument errors */
    {
        fogvol_mesh_desc d = mesh_desc(cube_v, 8, cube_i, 36);
        assert_int_equal(fogvol_validate_mesh(&d, NULL, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
        assert_int_equal(fogvol_validate_mesh(NULL, NULL, &rep), FOGVOL_ERROR_INVALID_ARGUMENT);
        d.positions = NULL;
        assert_int_equal(fogvol_validate_mesh(&d, NULL, &rep), FOGVOL_ERROR_INVALID_ARGUMENT);
        d = mesh_desc(cube_v, 8, NULL, 36);
        assert_int_equal(fogvol_validate_mesh(&d, NULL, &rep), FOGVOL_ERROR_INVALID_ARGUMENT);
        d = mesh_desc(cube_v, 0, cube_i, 36);
        assert_int_equal(fogvol_validate_mesh(&d, NULL, &rep), FOGVOL_ERROR_INVALID_ARGUMENT);
        d = mesh_desc(cube_v, -8, cube_i, 36);
        assert_int_equal(fogvol_validate_mesh(&d, NULL, &rep), FOGVOL_ERROR_INVALID_ARGUMENT);
        d = mesh_desc(cube_v, 8, cube_i, 0);
        assert_int_equal(fogvol_validate_mesh(&d, NULL, &rep), FOGVOL_ERROR_INVALID_ARGUMENT);
        d = mesh_desc(cube_v, 8, cube_i, 35);
        assert_int_equal(fogvol_validate_mesh(&d, NULL, &rep), FOGVOL_ERROR_INVALID_ARGUMENT);
        d = mesh_desc(cube_v, 8, cube_i, 34);
        assert_int_equal(fogvol_validate_mesh(&d, NULL, &rep), FOGVOL_ERROR_INVALID_ARGUMENT);
        d = mesh_desc(cube_v, 8, cube_i, 36);
        d.stride = 8; /* shorter than a position */
        assert_int_equal(fogvol_validate_mesh(&d, NULL, &rep), FOGVOL_ERROR_INVALID_ARGUMENT);
        d.stride = -12;
        assert_int_equal(fogvol_validate_mesh(&d, NULL, &rep), FOGVOL_ERROR_INVALID_ARGUMENT);
        d.stride = 12; /* explicit tight stride */
        assert_int_equal(fogvol_validate_mesh(&d, NULL, &rep), FOGVOL_SUCCESS);
        CHECK_NEAR(rep.volume, 8.0, 1e-12);
    }
}

static void test_mesh_nonmanifold(void **state)
{
    fogvol_mesh_report rep;
    (void)state;
    /* Three triangles on edge 0-1 (a fan): edge {0,1} has 3 users, the other 6 edges one. */
    {
        static const float v[5 * 3] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, -1, 0};
        static const uint32_t idx[9] = {0, 1, 2, 1, 0, 3, 0, 1, 4};
        assert_int_equal(validate(v, 5, idx, 9, &rep), FOGVOL_ERROR_INVALID_MESH);
        assert_int_equal(rep.nonmanifold_edges, 1);
        assert_int_equal(rep.open_edges, 6);
        assert_false(rep.closed);
        assert_false(rep.valid);
    }
    /* Two closed tetrahedra sharing the edge 0-1 (4 users), each outward:
       A = (0,0,0),(1,0,0),(0,1,0),(0,0,1): faces (0,2,1) -z, (0,1,3) -y, (0,3,2) -x, (1,2,3) (1,1,1);
       B = A rotated 180 degrees about x (y,z -> -y,-z): vertices 4 = (0,-1,0), 5 = (0,0,-1),
       same index pattern (0,4,1), (0,1,5), (0,5,4), (1,4,5). Volume 1/6 each. */
    {
        static const float v[6 * 3] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1};
        static const uint32_t idx[24] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3,
                                         0, 4, 1, 0, 1, 5, 0, 5, 4, 1, 4, 5};
        /* each tetrahedron alone is a valid hull of volume 1/6 */
        assert_int_equal(validate(v, 6, idx, 12, &rep), FOGVOL_SUCCESS);
        CHECK_NEAR(rep.volume, 1.0 / 6.0, 1e-12);
        assert_int_equal(validate(v, 6, idx + 12, 12, &rep), FOGVOL_SUCCESS);
        CHECK_NEAR(rep.volume, 1.0 / 6.0, 1e-12);
        assert_int_equal(validate(v, 6, idx, 24, &rep), FOGVOL_ERROR_INVALID_MESH);
        assert_int_equal(rep.nonmanifold_edges, 1);
        assert_int_equal(rep.open_edges, 0);
        assert_int_equal(rep.inconsistent_edges, 0);
        assert_int_equal(rep.components, 2);
        assert_false(rep.closed);
        assert_false(rep.valid);
        CHECK_NEAR(rep.volume, 1.0 / 3.0, 1e-12);
    }
    /* two separate cubes: 2 components, valid, volume 16 */
    {
        float v[16 * 3];
        uint32_t idx[72];
        int i;
        memcpy(v, cube_v, sizeof cube_v);
        for (i = 0; i < 24; ++i) v[24 + i] = cube_v[i] + (i % 3 == 0 ? 5.0f : 0.0f);
        memcpy(idx, cube_i, sizeof cube_i);
        for (i = 0; i < 36; ++i) idx[36 + i] = cube_i[i] + 8;
        assert_int_equal(validate(v, 16, idx, 72, &rep), FOGVOL_SUCCESS);
        assert_int_equal(rep.components, 2);
        CHECK_NEAR(rep.volume, 16.0, 1e-12);
        /* second cube inward: the first stays outward; flipped counts per part (0), but the
           mesh is not a valid volume (total volume 0) */
        for (i = 12; i < 24; ++i) flip(idx + 3 * i);
        assert_int_equal(validate(v, 16, idx, 72, &rep), FOGVOL_ERROR_INVALID_MESH);
        assert_int_equal(rep.flipped_faces, 0);
        CHECK_NEAR(rep.volume, 0.0, 1e-12);
        assert_false(rep.valid);
    }
}

static void test_mesh_torus(void **state)
{
    /* Torus R = 2, r = 0.5, nu = 8 segments around the axis, nv = 6 around the tube.
       p(u,v) = ((R + r cos v) cos u, (R + r cos v) sin u, r sin v); at (0,0) dp/du = +y,
       dp/dv = +z and y x z = +x points outward, so quad (a = (i,j), b = (i+1,j),
       c = (i+1,j+1), d = (i,j+1)) -> triangles (a,b,c), (a,c,d) are outward.
       Exact volume of this polyhedron (its quads are planar isosceles trapezoids): each of the
       nu wedges is swept by the cross-section polygon (regular nv-gon of circumradius r, centroid
       at distance R) between two half-planes; with position rho*c(s) + z*zhat, c(s) =
       s e0 + (1-s) e1, the Jacobian is rho*sin(2pi/nu), so a wedge holds
       sin(2pi/nu) * R * A_poly, A_poly = nv/2 r^2 sin(2pi/nv):
           V = nu sin(2pi/nu) * nv/2 sin(2pi/nv) * R r^2   (-> 2 pi^2 R r^2 as nu, nv grow). */
    enum { NU = 8, NV = 6 };
    const double R = 2.0, r = 0.5;
    float v[NU * NV * 3];
    uint32_t idx[NU * NV * 6];
    fogvol_mesh_report rep;
    double vexact, vsmooth;
    int i, j, t = 0;
    (void)state;
    for (i = 0; i < NU; ++i)
        for (j = 0; j < NV; ++j) {
            double u = 2.0 * PI_D * i / NU, w = 2.0 * PI_D * j / NV;
            v[3 * (i * NV + j) + 0] = (float)((R + r * cos(w)) * cos(u));
            v[3 * (i * NV + j) + 1] = (float)((R + r * cos(w)) * sin(u));
            v[3 * (i * NV + j) + 2] = (float)(r * sin(w));
        }
    for (i = 0; i < NU; ++i)
        for (j = 0; j < NV; ++j) {
            uint32_t a = (uint32_t)(i * NV + j), b = (uint32_t)(((i + 1) % NU) * NV + j),
                     c = (uint32_t)(((i + 1) % NU) * NV + (j + 1) % NV), d = (uint32_t)(i * NV + (j + 1) % NV);
            idx[t++] = a;
            idx[t++] = b;
            idx[t++] = c;
            idx[t++] = a;
            idx[t++] = c;
            idx[t++] = d;
        }
    vexact = NU * sin(2.0 * PI_D / NU) * (NV / 2.0) * sin(2.0 * PI_D / NV) * R * r * r;
    vsmooth = 2.0 * PI_D * PI_D * R * r * r;
    assert_int_equal(validate(v, NU * NV, idx, t, &rep), FOGVOL_SUCCESS);
    assert_int_equal(rep.triangles, 2 * NU * NV);
    assert_int_equal(rep.open_edges, 0);
    assert_int_equal(rep.components, 1);
    assert_true(rep.valid);
    CHECK_NEAR(rep.volume, vexact, 1e-5 * vexact); /* float vertices */
    /* and within the tessellation loss of the smooth torus: an inscribed polyhedron, smaller,
       by the factor (nu sin(2pi/nu)/2pi) (nv sin(2pi/nv)/2pi) = 0.9003 * 0.8270 = 0.745 */
    assert_true(rep.volume < vsmooth);
    assert_true(rep.volume > 0.74 * vsmooth);
    print_message("torus 8x6: volume %.6f, polyhedron %.6f, smooth torus %.6f\n", rep.volume, vexact, vsmooth);
    /* one triangle flipped in the torus */
    flip(idx + 3 * 17);
    assert_int_equal(validate(v, NU * NV, idx, t, &rep), FOGVOL_ERROR_INVALID_MESH);
    assert_int_equal(rep.flipped_faces, 1);
    assert_int_equal(rep.inconsistent_edges, 3);
}

/* counting / failing allocator */
typedef struct test_alloc {
    int calls, fail_at, live;
} test_alloc;

static void *ta_alloc(size_t size, void *ud)
{
    test_alloc *a = (test_alloc *)ud;
    a->calls++;
    if (a->fail_at > 0 && a->calls == a->fail_at) return NULL;
    a->live++;
    return malloc(size);
}

static void ta_free(void *p, void *ud)
{
    test_alloc *a = (test_alloc *)ud;
    if (p) a->live--;
    free(p);
}

static fogvol_result validate_shp(const shp_mesh *m, fogvol_mesh_report *rep)
{
    return validate(m->pos, m->vcount, (const uint32_t *)m->idx, m->icount, rep);
}

/* A prism over a self-intersecting "bowtie" polygon: (-3,-1.5) (2,1) (2,-1) (-3,1.5), z in [0,1].
   Its diagonals cross at the origin; the left lobe (area 4.5) is wound outward, the right lobe
   (area 2) inward: closed, consistent, one component, total volume 2.5 > 0, and yet the right lobe
   has winding number -1 (worked out by hand from the polygon's orientation). */
static shp_mesh bowtie_prism(void)
{
    static const float xy[4][2] = {{-3.0f, -1.5f}, {2.0f, 1.0f}, {2.0f, -1.0f}, {-3.0f, 1.5f}};
    shp_mesh m = shp__alloc(8, 24 + 12);
    unsigned *p = m.idx;
    int i;
    for (i = 0; i < 4; ++i) {
        shp__setv(&m, i, xy[i][0], xy[i][1], 0.0);
        shp__setv(&m, 4 + i, xy[i][0], xy[i][1], 1.0);
    }
    for (i = 0; i < 4; ++i) shp__quad(&p, i, (i + 1) % 4, 4 + (i + 1) % 4, 4 + i); /* sides */
    shp__tri(&p, 0, 2, 1); /* bottom, facing -z where the polygon runs counter-clockwise */
    shp__tri(&p, 0, 3, 2);
    shp__tri(&p, 4, 5, 6); /* top */
    shp__tri(&p, 4, 6, 7);
    return m;
}

/* Issue: one component wound inward, or an inverted lobe, while the total volume is positive.
   The decision is per region (winding number), never by the total: a cavity (an inward shell
   inside an outward one) is a valid volume, an inward part that nothing encloses is not. */
static void test_mesh_winding(void **state)
{
    fogvol_mesh_report rep;
    shp_mesh outer = shp_sphere(1.0f, 32, 16), inner = shp_sphere(0.5f, 32, 16), away = shp_sphere(0.5f, 32, 16);
    shp_mesh hollow = shp__zero(), apart = shp__zero(), bow = bowtie_prism(), good = bowtie_prism();
    float mv[16];
    int outer_tris = outer.icount / 3;
    (void)state;
    assert_non_null(outer.pos);
    /* hollow ball: outer outward, inner (radius 0.5) inward, inside it */
    shp_flip(&inner);
    assert_true(shp_append(&hollow, &outer));
    assert_true(shp_append(&hollow, &inner));
    assert_int_equal(validate_shp(&hollow, &rep), FOGVOL_SUCCESS);
    assert_int_equal(rep.components, 2);
    assert_int_equal(rep.inward_components, 1);
    assert_int_equal(rep.negative_winding, 0);
    assert_int_equal(rep.negative_triangle, -1);
    assert_true(rep.valid);
    /* the same inward sphere moved out of the ball (centre x = 3): total volume still positive
       (4.19 - 0.52), but the small sphere renders negative thickness */
    shp_flip(&away);
    shp_mat_translate(mv, 3.0f, 0.0f, 0.0f);
    shp_transform(&away, mv);
    assert_true(shp_append(&apart, &outer));
    assert_true(shp_append(&apart, &away));
    assert_int_equal(validate_shp(&apart, &rep), FOGVOL_ERROR_INVALID_MESH);
    assert_true(rep.closed && rep.consistent && !rep.inverted && rep.volume > 3.0);
    assert_int_equal(rep.inward_components, 1);
    assert_true(rep.negative_winding > 0);
    assert_true(rep.negative_triangle >= outer_tris); /* a triangle of the moved sphere */
    assert_false(rep.valid);
    /* the bowtie prism: one component, positive total, an inverted lobe */
    assert_int_equal(validate_shp(&bow, &rep), FOGVOL_ERROR_INVALID_MESH);
    assert_true(rep.closed && rep.consistent);
    assert_int_equal(rep.components, 1);
    assert_int_equal(rep.inward_components, 0);
    assert_true(fabs(rep.volume - 2.5) < 1e-6);
    assert_true(rep.negative_winding > 0);
    assert_true(rep.negative_triangle >= 0 && rep.negative_triangle < 12);
    /* moving the crossing out of the polygon (a plain quadrilateral) makes it valid */
    good.pos[3 * 1 + 1] = good.pos[3 * 5 + 1] = -1.0f; /* (2,1) -> (2,-1) and (2,-1) -> (2,1) */
    good.pos[3 * 2 + 1] = good.pos[3 * 6 + 1] = 1.0f;
    assert_int_equal(validate_shp(&good, &rep), FOGVOL_SUCCESS);
    assert_int_equal(rep.negative_winding, 0);
    shp_free(&outer);
    shp_free(&inner);
    shp_free(&away);
    shp_free(&hollow);
    shp_free(&apart);
    shp_free(&bow);
    shp_free(&good);
}

/* A box [lo, hi] whose faces are grids of n[axis] quads along each axis (per-face vertices, so
   the caller welds them with weld_distance), outward, or inward with inward = 1. */
static shp_mesh grid_box(const double lo[3], const double hi[3], const int n[3], int inward)
{
    int a, s, i, j, nv = 0, ni = 0;
    shp_mesh m;
    for (a = 0; a < 3; ++a) {
        int u = (a + 1) % 3, v = (a + 2) % 3;
        nv += 2 * (n[u] + 1) * (n[v] + 1);
        ni += 2 * 6 * n[u] * n[v];
    }
    m = shp__alloc(nv, ni);
    if (!m.pos) return m;
    nv = ni = 0;
    for (a = 0; a < 3; ++a)
        for (s = 0; s < 2; ++s) {
            int u = (a + 1) % 3, v = (a + 2) % 3, base = nv;
            for (j = 0; j <= n[v]; ++j)
                for (i = 0; i <= n[u]; ++i, ++nv) {
                    double c[3];
                    c[a] = s ? hi[a] : lo[a];
                    c[u] = lo[u] + (hi[u] - lo[u]) * i / n[u];
                    c[v] = lo[v] + (hi[v] - lo[v]) * j / n[v];
                    shp__setv(&m, nv, c[0], c[1], c[2]);
                }
            for (j = 0; j < n[v]; ++j)
                for (i = 0; i < n[u]; ++i) {
                    unsigned q[4], *p = m.idx + ni;
                    q[0] = (unsigned)(base + j * (n[u] + 1) + i); /* u x v = +axis: counter-clockwise */
                    q[1] = q[0] + 1;                              /* seen from +axis */
                    q[2] = q[1] + (unsigned)(n[u] + 1);
                    q[3] = q[0] + (unsigned)(n[u] + 1);
                    if (s == inward) shp__quad(&p, (int)q[0], (int)q[3], (int)q[2], (int)q[1]);
                    else shp__quad(&p, (int)q[0], (int)q[1], (int)q[2], (int)q[3]);
                    ni += 6;
                }
        }
    return m;
}

static fogvol_result validate_welded(const shp_mesh *m, fogvol_mesh_report *rep)
{
    fogvol_mesh_desc d = mesh_desc(m->pos, m->vcount, (const uint32_t *)m->idx, m->icount);
    d.weld_distance = 1e-6f;
    return fogvol_validate_mesh(&d, NULL, rep);
}

/* Issue 31 3a: parts built from quads exactly one probe-grid step wide. The probe grid divides
   the mesh's bounds in FOGVOL__WIND_GRID (32) steps per axis; with an outward box [-1,1]^3
   beside it, the inward box [2,3]x[-.5,.5]^2 of 8x16x16 quads has quads one step wide, so every
   probe ray that lands at the same offset in both of a quad's axes lies on its diagonal. */
static void test_mesh_winding_grid(void **state)
{
    static const double olo[3] = {-1, -1, -1}, ohi[3] = {1, 1, 1}, ilo[3] = {2, -.5, -.5}, ihi[3] = {3, .5, .5};
    static const int on[3] = {16, 32, 32}, in[3] = {8, 16, 16}, cube_n[3] = {32, 32, 32}, one[3] = {1, 1, 1};
    fogvol_mesh_report rep;
    shp_mesh outer = grid_box(olo, ohi, on, 0), inner = grid_box(ilo, ihi, in, 1), both = shp__zero();
    shp_mesh cube = grid_box(olo, ohi, cube_n, 0), plain = grid_box(ilo, ihi, one, 1), both1 = shp__zero();
    (void)state;
    assert_non_null(outer.pos);
    assert_non_null(inner.pos);
    assert_true(shp_append(&both, &outer));
    assert_true(shp_append(&both, &inner));
    assert_true(shp_append(&both1, &outer));
    assert_true(shp_append(&both1, &plain));
    /* each box alone: the outward one is valid, the inward one exposed (winding -1 inside) */
    assert_int_equal(validate_welded(&outer, &rep), FOGVOL_SUCCESS);
    CHECK_NEAR(rep.volume, 8.0, 1e-9);
    assert_int_equal(validate_welded(&inner, &rep), FOGVOL_ERROR_INVALID_MESH);
    /* the inward box as 12 triangles beside the grid box: refused (the probes are not all on diagonals) */
    assert_int_equal(validate_welded(&both1, &rep), FOGVOL_ERROR_INVALID_MESH);
    assert_int_equal(rep.inward_components, 1);
    /* the grid-aligned inward box beside the outward one: refused too, the bad triangle named */
    assert_int_equal(validate_welded(&both, &rep), FOGVOL_ERROR_INVALID_MESH);
    assert_true(rep.closed && rep.consistent);
    assert_int_equal(rep.components, 2);
    assert_int_equal(rep.inward_components, 1);
    CHECK_NEAR(rep.volume, 8.0 - 1.0, 1e-9);
    assert_true(rep.negative_winding > 0);
    assert_true(rep.negative_triangle >= outer.icount / 3);
    assert_false(rep.valid);
    /* a welded cube of 32x32 quads per face: valid (its probe rays all lie on quad diagonals) */
    assert_int_equal(validate_welded(&cube, &rep), FOGVOL_SUCCESS);
    assert_int_equal(rep.vertices, 6 * 32 * 32 + 2);
    CHECK_NEAR(rep.volume, 8.0, 1e-9);
    assert_int_equal(rep.negative_winding, 0);
    /* the same cube inward: refused */
    shp_flip(&cube);
    assert_int_equal(validate_welded(&cube, &rep), FOGVOL_ERROR_INVALID_MESH);
    /* an inward box [.5,3]x[-.5,.5]^2 of 20x16x16 quads (one probe-grid step each: the bounds are
       [-1,3]x[-1,1]^2) half inside the outward box [-1,1]^3: winding 0 where they overlap, -1 in
       [1,3]x[-.5,.5]^2; the probe just inside the inward part lands where they overlap, so the
       probe rays must see it */
    {
        static const double plo[3] = {.5, -.5, -.5}, phi[3] = {3, .5, .5};
        static const int pn[3] = {20, 16, 16};
        shp_mesh part = grid_box(plo, phi, pn, 1), box = grid_box(olo, ohi, one, 0);
        assert_true(shp_append(&box, &part));
        assert_int_equal(validate_welded(&box, &rep), FOGVOL_ERROR_INVALID_MESH);
        assert_int_equal(rep.inward_components, 1);
        assert_true(rep.negative_winding > 0);
        assert_true(rep.negative_triangle >= 0); /* the outward box's face x = 1 bounds the region too */
        shp_free(&part);
        shp_free(&box);
    }
    /* outward boxes [-1,1]^3 and [2,4]x[-1,1]^2 (bounds: steps 5/32 in x, 2/32 in y and z) and between
       them an inward box from 0.05 to 0.15 of a probe-grid cell in each axis: no probe ray (at 0.47
       to 0.52 of a cell) meets it, the probe just inside the inward part alone must see it */
    {
        static const double blo[3] = {2, -1, -1}, bhi[3] = {4, 1, 1};
        double tlo[3], thi[3];
        shp_mesh two = grid_box(olo, ohi, one, 0), b = grid_box(blo, bhi, one, 0), tiny;
        int c;
        for (c = 0; c < 3; ++c) {
            double lo = -1.0, step = c ? 2.0 / 32 : 5.0 / 32, i = c ? 10 : 16;
            tlo[c] = lo + (i + 0.05) * step;
            thi[c] = lo + (i + 0.15) * step;
        }
        tiny = grid_box(tlo, thi, one, 1);
        assert_true(shp_append(&two, &b));
        assert_int_equal(validate_welded(&two, &rep), FOGVOL_SUCCESS);
        assert_true(shp_append(&two, &tiny));
        assert_int_equal(validate_welded(&two, &rep), FOGVOL_ERROR_INVALID_MESH);
        assert_int_equal(rep.inward_components, 1);
        assert_int_equal(rep.negative_winding, 1);
        assert_true(rep.negative_triangle >= 24);
        shp_free(&two);
        shp_free(&b);
        shp_free(&tiny);
    }
    shp_free(&outer);
    shp_free(&inner);
    shp_free(&both);
    shp_free(&cube);
    shp_free(&plain);
    shp_free(&both1);
}

static void test_mesh_alloc_and_stride(void **state)
{
    fogvol_mesh_report rep;
    fogvol_mesh_desc d = mesh_desc(cube_v, 8, cube_i, 36);
    test_alloc ta;
    fogvol_allocator al;
    int n, total;
    (void)state;

    memset(&ta, 0, sizeof ta);
    al.alloc = ta_alloc;
    al.free = ta_free;
    al.user_data = &ta;
    assert_int_equal(fogvol_validate_mesh(&d, &al, &rep), FOGVOL_SUCCESS);
    assert_true(ta.calls > 0); /* the scratch came from our allocator */
    assert_int_equal(ta.live, 0);
    total = ta.calls;
    /* fail each allocation in turn: OUT_OF_MEMORY, nothing leaked */
    for (n = 1; n <= total; ++n) {
        memset(&ta, 0, sizeof ta);
        ta.fail_at = n;
        assert_int_equal(fogvol_validate_mesh(&d, &al, &rep), FOGVOL_ERROR_OUT_OF_MEMORY);
        assert_int_equal(ta.live, 0);
    }

    /* stride 24: position + normal per vertex, normals NaN (a reader ignoring the stride would
       see them). The block ends right after the last position (7*24 + 12 bytes), so ASan catches
       any read past it. */
    {
        const size_t bytes = 7 * 24 + 12;
        float *buf = (float *)malloc(bytes);
        int i;
        assert_non_null(buf);
        for (i = 0; i < 8; ++i) {
            memcpy(buf + 6 * i, cube_v + 3 * i, 12);
            if (i < 7) {
                buf[6 * i + 3] = (float)NAN;
                buf[6 * i + 4] = (float)NAN;
                buf[6 * i + 5] = (float)NAN;
            }
        }
        d = mesh_desc(buf, 8, cube_i, 36);
        d.stride = 24;
        assert_int_equal(fogvol_validate_mesh(&d, NULL, &rep), FOGVOL_SUCCESS);
        assert_int_equal(rep.nonfinite_vertices, 0);
        CHECK_NEAR(rep.volume, 8.0, 1e-12);
        assert_true(rep.valid);
        /* stretch the cube through the stride: x -> 3x gives a 6x2x2 box, volume 24 */
        for (i = 0; i < 8; ++i) buf[6 * i] *= 3.0f;
        assert_int_equal(fogvol_validate_mesh(&d, NULL, &rep), FOGVOL_SUCCESS);
        CHECK_NEAR(rep.volume, 24.0, 1e-12);
        free(buf);
    }
}

/* ------------------------------------------------------------------------ */
/* 9. result strings, renderer names                                        */
/* ------------------------------------------------------------------------ */

/* fogvol_renderer_is_software on renderer strings as drivers report them (GL_RENDERER, ANGLE's,
   Vulkan device names under zink): the CPU renderers by name, GPUs not (an LLVM in a GPU driver's
   name is not llvmpipe) */
static void test_software_renderer_names(void **state)
{
    static const struct {
        const char *name;
        int software;
    } t[] = {{"llvmpipe (LLVM 15.0.6, 256 bits)", 1},
             {"softpipe", 1},
             {"Software Rasterizer", 1},
             {"zink Vulkan 1.3(llvmpipe (LLVM 15.0.6, 256 bits) (MESA_LLVMPIPE))", 1},
             {"ANGLE (Google, Vulkan 1.3.0 (SwiftShader Device (Subzero) (0x0000C0DE)), SwiftShader driver-5.0.0)", 1},
             {"Google SwiftShader", 1},
             {"ANGLE (Microsoft, Microsoft Basic Render Driver Direct3D11 vs_5_0 ps_5_0, D3D11)", 1},
             {"GDI Generic", 1},
             {"Apple Software Renderer", 1},
             {"NVIDIA H200/PCIe/SSE2", 0},
             {"AMD Radeon RX 7900 XTX (radeonsi, navi31, LLVM 15.0.7, DRM 3.54, 6.5.0)", 0},
             {"Mesa Intel(R) UHD Graphics 620 (KBL GT2)", 0},
             {"Apple M1", 0},
             {"ANGLE (NVIDIA, NVIDIA GeForce RTX 3080 Direct3D11 vs_5_0 ps_5_0, D3D11)", 0},
             {"", 0}};
    size_t i;
    (void)state;
    for (i = 0; i < sizeof t / sizeof t[0]; ++i)
        assert_int_equal(fogvol_renderer_is_software(t[i].name), t[i].software);
    assert_int_equal(fogvol_renderer_is_software(NULL), 0);
}

static void test_result_strings(void **state)
{
    static const fogvol_result codes[] = {
        FOGVOL_SUCCESS,           FOGVOL_ERROR_INVALID_ARGUMENT, FOGVOL_ERROR_OUT_OF_MEMORY,
        FOGVOL_ERROR_BUFFER_TOO_SMALL, FOGVOL_ERROR_UNSUPPORTED, FOGVOL_ERROR_INVALID_MESH,
        FOGVOL_ERROR_INVALID_STATE, FOGVOL_ERROR_MISSING_FUNCTION, FOGVOL_ERROR_SHADER_COMPILE,
        FOGVOL_ERROR_SHADER_LINK, FOGVOL_ERROR_FRAMEBUFFER,    FOGVOL_ERROR_BACKEND,
        FOGVOL_ERROR_DEPTH_OVERFLOW};
    const int nc = (int)(sizeof codes / sizeof codes[0]);
    const char *unknown;
    int i, j;
    (void)state;
    assert_int_equal(nc, 13); /* 0 .. -12 */
    unknown = fogvol_result_string((fogvol_result)-99);
    assert_non_null(unknown);
    assert_true(strlen(unknown) > 0);
    assert_non_null(fogvol_result_string((fogvol_result)1));
    assert_non_null(fogvol_result_string(FOGVOL_RESULT_MAX_ENUM));
    assert_string_equal(fogvol_result_string((fogvol_result)-13), unknown);
    for (i = 0; i < nc; ++i) {
        const char *s = fogvol_result_string(codes[i]);
        assert_non_null(s);
        assert_true(strlen(s) > 0);
        assert_string_not_equal(s, unknown);
        assert_int_equal((int)codes[i], -i);
        for (j = 0; j < i; ++j) assert_string_not_equal(s, fogvol_result_string(codes[j]));
    }
    assert_string_equal(fogvol_result_string(FOGVOL_SUCCESS), "success");
    assert_non_null(strstr(fogvol_result_string(FOGVOL_ERROR_OUT_OF_MEMORY), "memory"));
    assert_non_null(strstr(fogvol_result_string(FOGVOL_ERROR_BUFFER_TOO_SMALL), "small"));
}


/* ---- the Vulkan dialect (FOGVOL_GLSL_VULKAN) ------------------------------------------------
   The layout a backend fills without reflection (fogvol_dialect_layout, fogvol_program_desc.layout)
   against what the Vulkan strings declare (the std140 pass block and the push constants, read from
   the text: std140 puts the n-th vec4 member at 16 n), against fogvol_pass.uniforms as the struct
   lays it out, and against the sampler units the backend table's documentation lists (written out
   here); and which programs exist: every one of GLSL 330 core but the framebuffer fetch's
   (FETCH_O, EXACT_SUM) and the per-sample ones, which the caps leave out on Vulkan. */
static const char *const g_unit_names[][2] = {
    {"fv_rg", "0"}, {"fv_blue", "1"}, {"fv_dither", "2"}, {"fv_opaque", "3"}, {"fv_opaque2", "4"},
    {"fv_density", "6"}, {"fv_lfront", "7"}, {"fv_back", "0"}, {"fv_front", "1"}, {"fv_colors", "2"},
    {"fv_back2", "4"}, {"fv_front2", "5"}, {"fv_ctex", "6"}, {"fv_pscene", "0"}, {"fv_pdepth", "1"},
    {"fv_pnormal", "2"}};

static void join_strings(const char *const *s, int n, char *buf, size_t cap)
{
    int i;
    buf[0] = 0;
    for (i = 0; i < n; ++i) {
        assert_true(strlen(buf) + strlen(s[i]) < cap);
        strcat(buf, s[i]);
    }
}

/* every "FV_BINDING(n) uniform TYPE NAME;" of a text: n is NAME's documented unit; returns the count */
static int check_bindings(const char *text)
{
    const char *p = text;
    int found = 0;
    while ((p = strstr(p, "FV_BINDING(")) != NULL) {
        char type[64], name[64], unit[8];
        size_t k;
        int matched = 0;
        if (sscanf(p, "FV_BINDING(%7[0-9]) uniform %63s %63[a-z0-9_];", unit, type, name) == 3) {
            for (k = 0; k < sizeof g_unit_names / sizeof g_unit_names[0]; ++k)
                if (strcmp(name, g_unit_names[k][0]) == 0) {
                    if (strcmp(unit, g_unit_names[k][1]) != 0) fail_msg("%s at unit %s, documented %s", name, unit,
                                                                         g_unit_names[k][1]);
                    matched = 1;
                }
            if (!matched) fail_msg("sampler %s has no documented unit", name);
            found++;
        } else if (strncmp(p, "FV_BINDING(unit)", 16) != 0) { /* (the macro's own definition) */
            fail_msg("unexpected FV_BINDING use: %.60s", p);
        }
        p += 11;
    }
    return found;
}

static void test_vulkan_layout(void **state)
{
    static const char *const draw_decl[FOGVOL_DRAW_VALUE_COUNT] = {"mat4 fv_mvp;", "vec4 fv_depth;", "vec4 fv_ext;",
                                                                  "vec4 fv_emit;", "float fv_sign;"};
    static const int draw_bytes[FOGVOL_DRAW_VALUE_COUNT] = {64, 16, 16, 16, 4};
    fogvol_uniform_layout l;
    fogvol_pass pass;
    fogvol_shader_desc sd;
    const char *s[FOGVOL_MAX_SHADER_STRINGS];
    static char text[65536];
    const char *block, *p;
    char want[128];
    int n, i, d, end = 0;
    (void)state;
    assert_int_equal(fogvol_dialect_layout(FOGVOL_GLSL_VULKAN, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    for (d = FOGVOL_GLSL_AUTO; d < FOGVOL_GLSL_COUNT; ++d) { /* GL dialects: by name, every field -1 */
        if (d == FOGVOL_GLSL_VULKAN) continue;
        assert_int_equal(fogvol_dialect_layout((fogvol_dialect)d, &l), FOGVOL_ERROR_UNSUPPORTED);
        assert_int_equal(l.pass_binding, -1);
        assert_int_equal(l.pass_offsets[FOGVOL_U_SPEEDUP], -1);
        assert_int_equal(l.draw_offsets[FOGVOL_DRAW_SIGN], -1);
        assert_int_equal(l.sampler_bindings[7], -1);
    }
    assert_string_equal(fogvol_dialect_name(FOGVOL_GLSL_VULKAN), "vulkan");
    assert_int_equal(fogvol_dialect_layout(FOGVOL_GLSL_VULKAN, &l), FOGVOL_SUCCESS);
    /* the pass block is fogvol_pass.uniforms as the struct holds it */
    assert_int_equal(l.pass_size, (int)sizeof pass.uniforms);
    for (i = 0; i < FOGVOL_U_COUNT; ++i)
        assert_int_equal(l.pass_offsets[i], (int)((const char *)pass.uniforms[i] - (const char *)pass.uniforms[0]));
    for (i = 0; i < FOGVOL_MAX_TEXTURE_UNITS; ++i) assert_int_equal(l.sampler_bindings[i], i);
    assert_true(l.draw_size <= 128); /* the push-constant size every Vulkan device has */
    /* ... and as the strings declare it */
    memset(&sd, 0, sizeof sd);
    sd.tier = FOGVOL_TIER_PS20;
    sd.program = FOGVOL_PROGRAM_FACE;
    sd.dialect = FOGVOL_GLSL_VULKAN;
    sd.stage = FOGVOL_STAGE_FRAGMENT;
    assert_int_equal(fogvol_shader_strings(&sd, s, &n), FOGVOL_SUCCESS);
    join_strings(s, n, text, sizeof text);
    snprintf(want, sizeof want, "layout(std140, set = 0, binding = %d) uniform fv_pass_block {\n", l.pass_binding);
    block = strstr(text, want);
    assert_non_null(block);
    p = block + strlen(want);
    for (i = 0; i < FOGVOL_U_COUNT; ++i) { /* std140: the i-th vec4 member at 16 i */
        snprintf(want, sizeof want, "    vec4 %s;\n", fogvol_uniform_name((fogvol_uniform)i));
        assert_true(strncmp(p, want, strlen(want)) == 0);
        assert_int_equal(l.pass_offsets[i], 16 * i);
        p += strlen(want);
    }
    assert_true(strncmp(p, "};", 2) == 0);
    assert_non_null(strstr(text, "layout(push_constant) uniform fv_draw_block {\n"));
    for (i = 0; i < FOGVOL_DRAW_VALUE_COUNT; ++i) {
        snprintf(want, sizeof want, "layout(offset = %d) %s", l.draw_offsets[i], draw_decl[i]);
        assert_non_null(strstr(text, want));
        if (l.draw_offsets[i] + draw_bytes[i] > end) end = l.draw_offsets[i] + draw_bytes[i];
    }
    assert_int_equal(l.draw_size, end);
    /* no loose uniforms: every uniform of a Vulkan text is a sampler with its binding, or a block */
    assert_true(check_bindings(text) >= 3);
}

static void test_vulkan_programs(void **state)
{
    static const unsigned specs[] = {0,
                                     FOGVOL_SPECIALIZE_NO_DENSITY,
                                     FOGVOL_SPECIALIZE_NO_DENSITY | FOGVOL_SPECIALIZE_NO_OPAQUE,
                                     FOGVOL_SPECIALIZE_EXP | FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE,
                                     FOGVOL_SPECIALIZE_COUNT | FOGVOL_SPECIALIZE_ORIGIN,
                                     FOGVOL_SPECIALIZE_FLOAT_O | FOGVOL_SPECIALIZE_DITHER | FOGVOL_SPECIALIZE_ENCODING(4),
                                     FOGVOL_SPECIALIZE_INLINE_RESOLVE,
                                     FOGVOL_SPECIALIZE_DOWNSAMPLE | FOGVOL_SPECIALIZE_FILTERED};
    static char text[65536];
    int t, p, st, k, exist = 0, samplers = 0;
    unsigned v;
    (void)state;
    for (t = 1; t < FOGVOL_TIER_COUNT; ++t)
        for (v = 0; v <= FOGVOL_VARIANT_ALL; ++v)
            for (p = 0; p < FOGVOL_PROGRAM_COUNT; ++p)
                for (st = 0; st < 2; ++st)
                    for (k = 0; k < (int)(sizeof specs / sizeof specs[0]); ++k) {
                        fogvol_shader_desc sd;
                        const char *s[FOGVOL_MAX_SHADER_STRINGS];
                        int n = -1, in330;
                        memset(&sd, 0, sizeof sd);
                        sd.tier = (fogvol_tier)t;
                        sd.variants = v;
                        sd.program = (fogvol_program)p;
                        sd.stage = (fogvol_stage)st;
                        sd.specialize = specs[k];
                        sd.dialect = FOGVOL_GLSL_330;
                        in330 = fogvol_shader_strings(&sd, s, &n) == FOGVOL_SUCCESS;
                        sd.dialect = FOGVOL_GLSL_VULKAN;
                        assert_int_equal(fogvol_shader_strings(&sd, s, &n),
                                         in330 ? FOGVOL_SUCCESS : FOGVOL_ERROR_UNSUPPORTED);
                        if (!in330) continue;
                        join_strings(s, n, text, sizeof text);
                        assert_true(strncmp(text, "#version 450\n", 13) == 0);
                        samplers += check_bindings(text);
                        ++exist;
                        /* the framebuffer fetch and per-sample shading: not in Vulkan's dialect */
                        sd.specialize = specs[k] | FOGVOL_SPECIALIZE_FETCH_O;
                        assert_int_equal(fogvol_shader_strings(&sd, s, &n), FOGVOL_ERROR_UNSUPPORTED);
                        sd.specialize = specs[k] | FOGVOL_SPECIALIZE_EXACT_SUM;
                        assert_int_equal(fogvol_shader_strings(&sd, s, &n), FOGVOL_ERROR_UNSUPPORTED);
                        sd.specialize = specs[k];
                        sd.samples = 4;
                        assert_int_equal(fogvol_shader_strings(&sd, s, &n), FOGVOL_ERROR_UNSUPPORTED);
                    }
    print_message("# %d Vulkan shaders exist where GLSL 330 core has them; %d sampler bindings checked\n", exist,
                  samplers);
    assert_true(exist > 1000);
    {
        const char *s[FOGVOL_MAX_SHADER_STRINGS];
        int n = 0;
        assert_int_equal(fogvol_post_shader_strings(FOGVOL_POST_OUTLINES, 1, FOGVOL_GLSL_VULKAN, FOGVOL_STAGE_FRAGMENT,
                                                    s, &n),
                         FOGVOL_SUCCESS);
        join_strings(s, n, text, sizeof text);
        assert_int_equal(check_bindings(text), 2); /* fv_pdepth, fv_pnormal */
        assert_int_equal(fogvol_analytic_shader_strings(FOGVOL_GLSL_VULKAN, FOGVOL_STAGE_VERTEX, 0, s, &n),
                         FOGVOL_SUCCESS);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_encoding_table),
        cmocka_unit_test(test_constants),
        cmocka_unit_test(test_hand_encodings),
        cmocka_unit_test(test_sums),
        cmocka_unit_test(test_dither),
        cmocka_unit_test(test_textures),
        cmocka_unit_test(test_color_ramps),
        cmocka_unit_test(test_color_ramp_auto_range),
        cmocka_unit_test(test_mesh_cube),
        cmocka_unit_test(test_mesh_nonmanifold),
        cmocka_unit_test(test_mesh_torus),
        cmocka_unit_test(test_mesh_winding),
        cmocka_unit_test(test_mesh_winding_grid),
        cmocka_unit_test(test_mesh_alloc_and_stride),
        cmocka_unit_test(test_result_strings),
        cmocka_unit_test(test_software_renderer_names),
        cmocka_unit_test(test_vulkan_layout),
        cmocka_unit_test(test_vulkan_programs),
    };
    /* CPU_TEST_FILTER: a cmocka pattern (* and ?), e.g. for the quick runs under valgrind */
    if (getenv("CPU_TEST_FILTER")) cmocka_set_test_filter(getenv("CPU_TEST_FILTER"));
    return cmocka_run_group_tests_name("cpu", tests, NULL, NULL);
}
