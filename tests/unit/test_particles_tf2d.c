/* test_particles_tf2d.c — the CPU bake of the 2D curvature transfer function
 * (renderer/particles/particles_tf2d.h): a widget's centre is its colour at
 * alpha 1; outside every radius the table is the ink; a later widget wins
 * over an earlier one; the falloff (1 - q²)² at q = 1/2; the unreachable
 * half k2 > k1 equals the diagonal; scaling range, centres and radii by 2
 * gives the same table. Then the five fixed points the browser test checks
 * the page's JS rule at (web/tf2d_editor.js, tests/browser/test_browser.cjs:
 * the values below are the ones it hard-codes). Last, with GL (llvmpipe is
 * fine): pt_tf2d bakes a set's table only when it is on and its function or
 * ink changed, and the texture holds the CPU bake byte for byte.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gpu/sl_gpu.h"
#include "particles/particles_tf2d.h"
#include "sl_test.h"

#define N PT_TF2D_SIZE

static uint8_t table[N * N * 4], other[N * N * 4];

static const uint8_t *texel(const uint8_t *t, int i, int j)
{
    return t + ((size_t)j * N + i) * 4;
}

static sl_transfer_function_2d one_widget(double range, double k1, double k2, double radius, double r, double g,
                                          double b, double a)
{
    sl_transfer_function_2d tf = {.count = 1, .range = range};
    double w[7] = {k1, k2, radius, r, g, b, a};
    memcpy(tf.widget[0], w, sizeof w);
    return tf;
}

static int same_rgb(const uint8_t *t, double r, double g, double b)
{
    return t[0] == (uint8_t)lround(r * 255) && t[1] == (uint8_t)lround(g * 255) && t[2] == (uint8_t)lround(b * 255) &&
           t[3] == 255;
}

/* The browser test's points: a three-widget function over a grey ink,
 * overlapping widgets, each point a texel centre of range 0.5. */
static const sl_transfer_function_2d js_tf = {
    .count = 3,
    .range = 0.5,
    .widget = {{0.2, 0.0, 0.25, 1.0, 0.2, 0.1, 0.9},
               {0.0, -0.2, 0.3, 0.1, 0.3, 1.0, 0.8},
               {0.15, -0.1, 0.15, 0.2, 0.9, 0.3, 0.6}},
};
static const float js_ink[3] = {0.5f, 0.5f, 0.5f};
static const int js_texel[5][2] = {{44, 32}, {32, 20}, {41, 25}, {36, 30}, {60, 2}};
static const double js_expect[5][3] = {
    {0.873999834, 0.292935517, 0.161415202}, /* (0.1953125, 0.0078125) */
    {0.183359193, 0.341679597, 0.895801008}, /* (0.0078125, -0.1796875) */
    {0.341540717, 0.667945805, 0.387048011}, /* (0.1484375, -0.1015625) */
    {0.508428272, 0.412202012, 0.483200028}, /* (0.0703125, -0.0234375) */
    {0.500000000, 0.500000000, 0.500000000}, /* (0.4453125, -0.4609375): outside every widget */
};

static void test_textures(void)
{
    sl_err err = {0};
    sl_gpu *gpu = NULL;
    if (sl_gpu_create(&(sl_gpu_desc){.quiet = 1}, &gpu, &err) != SL_OK) {
        SL_CHECK_MSG(0, "sl_gpu_create: %s", err.message);
        return;
    }
    pt_tf2d t;
    SL_CHECK(pt_tf2d_init(&t, &err) == SL_OK);
    sl_transfer_function_2d def;
    sl_transfer_function_2d_preset(SL_TF2D_PRESET_RIDGES_VALLEYS, &def);
    float ink[3] = {0.95f, 0.95f, 0.9f};
    pt_curvature_lookup c = pt_tf2d_lookup(&t, 0, 0, &def, ink, 0.5);
    SL_CHECK(!c.on && c.table == 0 && t.bakes == 0); /* off: no bake */
    c = pt_tf2d_lookup(&t, 0, 1, &def, ink, 0.5);
    SL_CHECK(c.on && c.table == t.tex[0] && c.range == 0.5f && c.min_spacing == 0.5f && t.bakes == 1);
    pt_tf2d_lookup(&t, 0, 1, &def, ink, 0.25); /* same function and ink: no bake */
    SL_CHECK(t.bakes == 1);
    pt_tf2d_lookup(&t, 1, 1, &def, ink, 0.5);  /* another set: its own table */
    SL_CHECK(t.bakes == 2);
    ink[1] = 0.5f;
    pt_tf2d_lookup(&t, 0, 1, &def, ink, 0.5);  /* the ink changed */
    SL_CHECK(t.bakes == 3);
    def.widget[1][6] = 0.5;
    c = pt_tf2d_lookup(&t, 0, 1, &def, ink, 0.5); /* the function changed */
    SL_CHECK(t.bakes == 4);
    pt_tf2d_bake(&def, ink, table);
    memset(other, 0, sizeof other);
    glGetTextureImage(c.table, 0, GL_RGBA, GL_UNSIGNED_BYTE, (GLsizei)sizeof other, other);
    SL_CHECK_MSG(memcmp(table, other, sizeof table) == 0, "the texture of set 0 differs from the CPU bake");
    SL_CHECK(sl_gl_check_errors("tf2d textures", &err) == SL_OK);
    pt_tf2d_deinit(&t);
    pt_tf2d_deinit(&t); /* twice is fine */
    sl_gpu_destroy(gpu);
}

int main(int argc, char **argv)
{
    const float ink[3] = {0.25f, 0.5f, 0.75f};
    double c[3];

    /* Centre = rgb at alpha 1 (a texel centre, so the table has it too). */
    double k1 = pt_tf2d_texel_center(0.5, 38), k2 = pt_tf2d_texel_center(0.5, 25);
    sl_transfer_function_2d tf = one_widget(0.5, k1, k2, 0.2, 1.0, 0.0, 0.0, 1.0);
    pt_tf2d_eval(&tf, ink, k1, k2, c);
    SL_CHECK(c[0] == 1.0 && c[1] == 0.0 && c[2] == 0.0);
    pt_tf2d_bake(&tf, ink, table);
    SL_CHECK(same_rgb(texel(table, 38, 25), 1.0, 0.0, 0.0));
    /* Falloff: at q = 1/2 the weight is (1 - 1/4)² = 0.5625. */
    pt_tf2d_eval(&tf, ink, k1 + 0.1, k2, c);
    SL_CHECK_NEAR(c[0], 0.25 + 0.5625 * 0.75, 1e-12);
    /* Outside the radius: the ink, exactly; in the table every reachable
     * texel farther than the radius is the ink. */
    pt_tf2d_eval(&tf, ink, k1 + 0.2000001, k2, c);
    SL_CHECK(c[0] == 0.25 && c[1] == 0.5 && c[2] == 0.75);
    int outside = 0, outside_ok = 0;
    for (int j = 0; j < N; j++)
        for (int i = j; i < N; i++) {
            double d1 = pt_tf2d_texel_center(0.5, i) - k1, d2 = pt_tf2d_texel_center(0.5, j) - k2;
            if (d1 * d1 + d2 * d2 > 0.2 * 0.2) {
                outside++;
                outside_ok += same_rgb(texel(table, i, j), ink[0], ink[1], ink[2]);
            }
        }
    SL_CHECK_MSG(outside > 1000 && outside_ok == outside, "%d of %d texels outside the radius are the ink", outside_ok,
                 outside);

    /* A later widget wins where both are full. */
    sl_transfer_function_2d two = one_widget(0.5, k1, k2, 0.2, 1.0, 0.0, 0.0, 1.0);
    double w2[7] = {k1, k2, 0.1, 0.0, 1.0, 0.0, 1.0};
    memcpy(two.widget[1], w2, sizeof w2);
    two.count = 2;
    pt_tf2d_eval(&two, ink, k1, k2, c);
    SL_CHECK(c[0] == 0.0 && c[1] == 1.0 && c[2] == 0.0);
    pt_tf2d_bake(&two, ink, table);
    SL_CHECK(same_rgb(texel(table, 38, 25), 0.0, 1.0, 0.0));

    /* The unreachable half (k2 > k1, row j > column i) holds the diagonal's
     * value: at its projection, so texel (i, j) = texel (m, m) for i + j = 2m,
     * on the default function over set 0's default ink. */
    sl_transfer_function_2d def;
    sl_transfer_function_2d_preset(SL_TF2D_PRESET_RIDGES_VALLEYS, &def);
    const float ink0[3] = {0.95f, 0.95f, 0.9f};
    pt_tf2d_bake(&def, ink0, table);
    int upper = 0, upper_ok = 0, differs = 0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < j; i++) {
            if ((i + j) % 2)
                continue;
            upper++;
            upper_ok += memcmp(texel(table, i, j), texel(table, (i + j) / 2, (i + j) / 2), 4) == 0;
            differs += memcmp(texel(table, j, i), texel(table, (i + j) / 2, (i + j) / 2), 4) != 0;
        }
    SL_CHECK_MSG(upper == 992 && upper_ok == upper, "%d of %d unreachable texels equal the diagonal", upper_ok, upper);
    SL_CHECK_MSG(differs > 100, "the reachable mirror differs from the diagonal at %d texels", differs);
    SL_CHECK(!same_rgb(texel(table, 32, 24), 0.95, 0.95, 0.9)); /* the valley darkens (0, -0.125) */

    /* Range scaling: range, centres and radii x2 give the same table. */
    sl_transfer_function_2d big = def;
    big.range *= 2;
    for (int k = 0; k < big.count; k++)
        for (int q = 0; q < 3; q++)
            big.widget[k][q] *= 2;
    pt_tf2d_bake(&big, ink0, other);
    SL_CHECK(memcmp(table, other, sizeof table) == 0);
    /* ... and the same widgets over a range x2 are half as wide in texels. */
    sl_transfer_function_2d wide = def;
    wide.range *= 2;
    pt_tf2d_bake(&wide, ink0, other);
    SL_CHECK(memcmp(table, other, sizeof table) != 0);

    /* The browser test's five points (`--print` writes them). */
    int print = argc > 1 && strcmp(argv[1], "--print") == 0;
    pt_tf2d_bake(&js_tf, js_ink, table);
    for (int p = 0; p < 5; p++) {
        double a = pt_tf2d_texel_center(0.5, js_texel[p][0]), b = pt_tf2d_texel_center(0.5, js_texel[p][1]);
        pt_tf2d_eval(&js_tf, js_ink, a, b, c);
        if (print)
            printf("    {%.9f, %.9f, %.9f}, /* (%.9g, %.9g) */\n", c[0], c[1], c[2], a, b);
        for (int q = 0; q < 3; q++)
            SL_CHECK_NEAR(c[q], js_expect[p][q], 1e-8);
        SL_CHECK(same_rgb(texel(table, js_texel[p][0], js_texel[p][1]), c[0], c[1], c[2]));
    }
    test_textures();
    SL_TEST_END();
}
