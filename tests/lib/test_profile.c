/*
 * test_profile.c - the edge-profile model (lib/profile.c) on exact limb
 * frames (support.c, sup_edge_render): a line put off the silhouette by a
 * known shift must come back to the silhouette; per modelled effect (flat
 * step, optical blur, motion blur across, contour angle, Lambertian limb),
 * the measured blur, the noise estimate, and bad input.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdlib.h>
#include <math.h>
#include <string.h>
#include <cmocka.h>
#include "support.h"

static cdsp_profile_ws pws;

/* Fit along a line shifted by `shift` px toward the pipe from the true
 * silhouette, over 80 px of contour through the frame's centre; returns the
 * status and fills *pr. */
static cdsp_status fit_image(const sup_edge_spec *e, const cdsp_image *img, const double np[2], const double l[3],
                             double shift, cdsp_profile *pr)
{
    cdsp_real L[3], ends[2][2], pin[2];
    cdsp_profile_params pp;
    double c0[2] = {(e->width - 1) / 2.0 + e->offset_px * np[0], (e->height - 1) / 2.0 + e->offset_px * np[1]};
    double sgn = l[0] * np[0] + l[1] * np[1] > 0 ? 1 : -1; /* (a, b) toward the pipe? */
    L[0] = (cdsp_real)l[0];
    L[1] = (cdsp_real)l[1];
    L[2] = (cdsp_real)(l[2] - sgn * shift);
    ends[0][0] = (cdsp_real)(c0[0] - 40 * np[1]);
    ends[0][1] = (cdsp_real)(c0[1] + 40 * np[0]);
    ends[1][0] = (cdsp_real)(c0[0] + 40 * np[1]);
    ends[1][1] = (cdsp_real)(c0[1] - 40 * np[0]);
    pin[0] = (cdsp_real)(c0[0] + e->radius_px * np[0]);
    pin[1] = (cdsp_real)(c0[1] + e->radius_px * np[1]);
    cdsp_profile_params_default(&pp);
    return cdsp_profile_fit(img, L, pin, (const cdsp_real(*)[2])ends, &pp, &pws, pr);
}

static cdsp_status fit_shifted(const sup_edge_spec *e, double shift, cdsp_profile *pr)
{
    cdsp_image img;
    double np[2], l[3];
    cdsp_status st;
    void *buf = sup_edge_render(e, &img, np, l);
    assert_non_null(buf);
    st = fit_image(e, &img, np, l, shift, pr);
    free(buf);
    return st;
}

static void spec16(sup_edge_spec *e)
{
    sup_edge_spec_default(e);
    e->bits = 16;
    e->pipe = 160 * 257;
    e->background = 60 * 257;
    e->offset_px = 0.3;
}

/* Flat sides: the model is exact, whatever the blur and angle. What is left
 * is 16-bit rounding (~1e-5 px over the window) and the iteration's stop
 * (1e-4 px): 2e-4; measured <= 9.3e-5 px in double (row 1). Float: the
 * window's integral (~1e7 gray levels x px) keeps ~6e-8 relative, 0.6 gray
 * level x px over the contrast 25700: 2e-5 px per rounding, a dozen of them
 * on the way, plus the same stop: 3e-4; measured <= 1.1e-4 px (row 1; it
 * allowed 2e-3). The blur: the
 * sigma of optics, motion box (L^2/12) and pixel footprint (1/12), within
 * 4.5 % (measured 0.0-3.4 %, the most at 45 degrees: the footprint's
 * trapezoid is not a Gaussian, which the moment formula assumes). */
static void test_flat_exact(void **state)
{
    static const struct {
        double angle, blur, motion, shift;
    } rows[] = {
        {0.7, 0.7, 0, 0.4},  {22.5, 0.7, 0, -0.3}, {45, 0.7, 0, 0.25}, {89.3, 0.7, 0, 0.5},
        {0.7, 3, 0, 0.8},    {45, 3, 0, -0.6},     {0.7, 0.7, 15, 2.5}, {67.5, 0.7, 15, -2.0},
        {0.7, 0.5, 0, 0},
    };
#ifdef CDSP_SINGLE
    const double tol = 3e-4;
#else
    const double tol = 2e-4;
#endif
    size_t r;
    (void)state;
    for (r = 0; r < sizeof rows / sizeof rows[0]; r++) {
        sup_edge_spec e;
        cdsp_profile pr;
        double want_blur;
        spec16(&e);
        e.angle_deg = rows[r].angle;
        e.blur_px = rows[r].blur;
        e.motion_px = rows[r].motion;
        assert_int_equal(fit_shifted(&e, rows[r].shift, &pr), CDSP_OK);
        want_blur = sqrt(rows[r].blur * rows[r].blur + 1.0 / 12 + rows[r].motion * rows[r].motion / 12);
        if (getenv("CDSP_TEST_VERBOSE"))
            print_message("row %zu: offset %.6f (want %.6f) blur %.4f (want %.4f)\n", r, (double)pr.offset,
                          -rows[r].shift, (double)pr.blur, want_blur);
        if (fabs((double)pr.offset + rows[r].shift) > tol)
            fail_msg("row %zu: offset %.6f, want %.6f (tol %g)", r, (double)pr.offset, -rows[r].shift, tol);
        if (fabs((double)pr.blur / want_blur - 1) > 0.045)
            fail_msg("row %zu: blur %.4f, want %.4f", r, (double)pr.blur, want_blur);
        assert_true(fabs((double)pr.contrast - 100 * 257) < 0.01 * 100 * 257);
    }
}

/* A Lambertian limb (shading ~ sqrt(distance) at the limb): the detector's
 * line is 0.3-0.5 px inside the pipe on these (measured by make bench's
 * study); the model takes the shading as A + B s + C sqrt(s (2 Rc - s))
 * and the blur's effect on it to second order. What is left comes from the
 * blur estimate: measured 0.0012, 0.0008 px (ambient 0.6; side light) and
 * 0.0044 px (ambient 0.3, light toward the viewer: the strongest
 * square-root term), double and float alike, at 0 degrees (one subpixel
 * phase; 0.0003, 0.0003, 0.009 px at 0.7 degrees); tolerances 2e-3,
 * 1.5e-3 and 0.01 px. The last was 0.08 px (measured 0.065) while the
 * blur's first moment was taken over the whole window, where the limb's
 * curvature inflated it by ~20 %; it is now taken over the blur zone. */
static void test_lambertian_limb(void **state)
{
    static const struct {
        double ambient, ln, lv, tol;
    } rows[] = {
        {0.6, 0.3, 0.95, 2e-3},
        {0.3, 0.7, 0.71, 1.5e-3},
        {0.3, 0.3, 0.95, 0.01},
    };
    size_t r;
    (void)state;
    for (r = 0; r < sizeof rows / sizeof rows[0]; r++) {
        sup_edge_spec e;
        cdsp_profile pr;
        spec16(&e);
        e.ambient = rows[r].ambient;
        e.light_n = rows[r].ln;
        e.light_v = rows[r].lv;
        assert_int_equal(fit_shifted(&e, 0.4, &pr), CDSP_OK);
        if (getenv("CDSP_TEST_VERBOSE"))
            print_message("row %zu: offset %.5f (want -0.4) blur %.4f shadow %.2f chi2 %.3f\n", r,
                          (double)pr.offset, (double)pr.blur, (double)pr.shadow, (double)pr.fit_chi2);
        if (fabs((double)pr.offset + 0.4) > rows[r].tol)
            fail_msg("row %zu: offset %.5f, want -0.4 (tol %g)", r, (double)pr.offset, rows[r].tol);
    }
}

/* A shaded limb under a blur wider than the detector's window (optical
 * 3 px, a 15 px motion blur across the contour): the area balance's pipe
 * side, fitted beyond the blur zone (12 px at sigma 3; 3 px of fit zone
 * left at 15 px of motion once the line is 4 px off) and extrapolated to
 * the silhouette, misfits (fit_chi2 0.17-5) or puts it 0.02-0.12 px off
 * (make bench-accuracy); the forward model (O = K * S fitted to every bin,
 * K a Gaussian through a box) puts it back. The line starts where the
 * detector put it (make bench-accuracy's cells: +0.3..+0.9 px at optical
 * 3, +-4.3..5 px at 15 px of motion). What is left comes from the
 * kernel's shape (the pixel's footprint, a box or a trapezoid on the
 * normal, taken into the Gaussian) and the grid of 1/8 px the basis is
 * interpolated on: measured 4.8e-4, 3.5e-4, 0, 7.8e-4, 1.0e-3, 1.9e-4,
 * 2.6e-4, 1e-5 px in double, float within 5e-5 of those; tolerance
 * 2e-3 px (the area balance before: 0.021, 0.017, 0.0017, 0.052, 0.065,
 * 0.0067, 2.0, 3.4 px off, main's library on this test). The
 * blur (the kernel's sigma)
 * within 1 % of optics, motion and footprint (measured <= 0.25 %);
 * fit_chi2 below max_fit_chi2, so that the frame path moves the line
 * (cdsp_profile_applies). */
static void test_wide_blur_limb(void **state)
{
    static const struct {
        double ambient, ln, lv, blur, motion, angle, pipe, bg, shift, tol;
    } rows[] = {
        {0.3, 0.7, 0.71, 3, 0, 0.7, 160, 60, 0.6, 2e-3},
        {0.3, 0.7, 0.71, 3, 0, 45, 160, 60, 0.6, 2e-3},
        {0.6, 0.3, 0.95, 3, 0, 22.5, 40, 160, -0.3, 2e-3},
        {0.6, 0.3, 0.95, 0.7, 15, 0.7, 160, 60, 4.3, 2e-3},
        {0.3, 0.7, 0.71, 0.7, 15, 22.5, 160, 60, 4.6, 2e-3},
        {0.3, 0.7, 0.71, 0.7, 15, 45, 40, 160, -4.4, 2e-3},
        /* a faint limb under strong shading (10 gray levels below the
         * background at the pipe's middle, 39 at the limb): the first
         * moment's blur fell to its floor there and the forward model
         * starts from the profile's slope */
        {0.3, 0.3, 0.95, 3, 0, 22.5, 60, 70, -0.52, 2e-3},
        {0.3, 0.3, 0.95, 0.7, 7, 45, 60, 70, -1.36, 2e-3},
    };
    size_t r;
    (void)state;
    for (r = 0; r < sizeof rows / sizeof rows[0]; r++) {
        sup_edge_spec e;
        cdsp_profile pr;
        cdsp_profile_params pp;
        double want_blur;
        spec16(&e);
        e.ambient = rows[r].ambient;
        e.light_n = rows[r].ln;
        e.light_v = rows[r].lv;
        e.blur_px = rows[r].blur;
        e.motion_px = rows[r].motion;
        e.angle_deg = rows[r].angle;
        e.pipe = rows[r].pipe * 257;
        e.background = rows[r].bg * 257;
        assert_int_equal(fit_shifted(&e, rows[r].shift, &pr), CDSP_OK);
        want_blur = sqrt(rows[r].blur * rows[r].blur + 1.0 / 12 + rows[r].motion * rows[r].motion / 12);
        cdsp_profile_params_default(&pp);
        if (getenv("CDSP_TEST_VERBOSE"))
            print_message("row %zu: offset %.5f (want %.5f) blur %.4f (want %.4f) chi2 %.3g flat %d\n", r,
                          (double)pr.offset, -rows[r].shift, (double)pr.blur, want_blur, (double)pr.fit_chi2, pr.flat);
        if (fabs((double)pr.offset + rows[r].shift) > rows[r].tol)
            fail_msg("row %zu: offset %.5f, want %.5f (tol %g)", r, (double)pr.offset, -rows[r].shift, rows[r].tol);
        if (fabs((double)pr.blur / want_blur - 1) > 0.01)
            fail_msg("row %zu: blur %.4f, want %.4f", r, (double)pr.blur, want_blur);
        if (!cdsp_profile_applies(&pr, &pp, 4))
            fail_msg("row %zu: not applied (fit_chi2 %.3g, flat %d)", r, (double)pr.fit_chi2, pr.flat);
    }
}

/* Flat sides under a blur wider than the detector's window keep the area
 * balance, exact there whatever the kernel, not the forward model: on
 * noise-free 8-bit frames at 45 degrees the pixel's footprint (a
 * trapezoid on the normal) through a 7 px motion blur is no Gaussian
 * through a box, the forward model's limb term took up the difference
 * (fit_chi2 0.29: not applied, the detector's line 0.77 px off kept) while
 * the area balance, its straight side fitted over 10 px, is within
 * 0.003 px (make bench-accuracy). Contrast 150, both polarities, the
 * line 0.8 px off as the detector put it; measured 0.0030 px at 45
 * degrees, 0.0002 at 22.5 and 67.5, double and float alike; tolerance
 * 0.006 px, and fit_chi2 within max_fit_chi2 (the forward model in their
 * place, commit 66dea4d: 0.017 px off, fit_chi2 0.29, at 45 degrees). (At
 * contrast 40 the 8-bit
 * rounding leaves the area balance itself 0.054 px off at 45 degrees,
 * on main too.) */
static void test_wide_blur_flat(void **state)
{
    static const struct {
        double pipe, bg, angle;
    } rows[] = {{210, 60, 45}, {60, 210, 45}, {210, 60, 22.5}, {60, 210, 67.5}};
    size_t r;
    (void)state;
    for (r = 0; r < sizeof rows / sizeof rows[0]; r++) {
        sup_edge_spec e;
        cdsp_profile pr;
        cdsp_profile_params pp;
        sup_edge_spec_default(&e);
        e.offset_px = 0.3;
        e.angle_deg = rows[r].angle;
        e.pipe = rows[r].pipe;
        e.background = rows[r].bg;
        e.motion_px = 7;
        assert_int_equal(fit_shifted(&e, 0.8, &pr), CDSP_OK);
        cdsp_profile_params_default(&pp);
        if (getenv("CDSP_TEST_VERBOSE"))
            print_message("row %zu: offset %.5f (want -0.8) blur %.4f chi2 %.3g flat %d applies %d\n", r,
                          (double)pr.offset, (double)pr.blur, (double)pr.fit_chi2, pr.flat,
                          cdsp_profile_applies(&pr, &pp, 4));
        if (fabs((double)pr.offset + 0.8) > 0.006)
            fail_msg("row %zu: offset %.5f, want -0.8 (tol %g)", r, (double)pr.offset, 0.006);
        if (!cdsp_profile_applies(&pr, &pp, 4))
            fail_msg("row %zu: not applied (fit_chi2 %.3g, flat %d)", r, (double)pr.fit_chi2, pr.flat);
    }
}

/* A limb in shadow (light from behind the limb, l_n < 0): the Lambertian
 * term is clipped to 0 up to the terminator tan(phi_t) = -l_n / l_v,
 * s_t = Rc (1 - cos phi_t) from the silhouette, so the pipe side is flat
 * there and lit beyond, with a kink. The unclipped model fitted that kink
 * with its square root (chi-square 1.2, the silhouette 0.2 px off on the
 * rack's frames, make bench-rack); the model now places the terminator
 * (shadow) and ends the silhouette's window before it. Ambient 0.4, the
 * rack's light (l_n -0.65, l_v 0.62: phi_t 46.4 degrees), pipe 250 on 60
 * (100 gray levels of contrast in the shadow), noise-free 16 bit, limb
 * radii 40 and 50 px (terminator 12.4, 15.5 px). Measured: offset within
 * 5e-5 px of the silhouette in double, 3.2e-4 px in float (the RSS of
 * the terminator's search is flat to float's precision near its
 * minimum), terminator within 0.006 px (float 0.009); tolerances 1.5e-4
 * and 1e-3 px (3x), 0.03 px. */
static void test_shadowed_limb(void **state)
{
    static const double radii[] = {40, 50}, angles[] = {0.7, 22.5};
#ifdef CDSP_SINGLE
    const double tol = 1e-3;
#else
    const double tol = 1.5e-4;
#endif
    size_t r, a;
    (void)state;
    for (r = 0; r < 2; r++)
        for (a = 0; a < 2; a++) {
            sup_edge_spec e;
            cdsp_profile pr;
            double phi_t, want_st;
            spec16(&e);
            e.pipe = 250 * 257;
            e.ambient = 0.4;
            e.light_n = -0.65;
            e.light_v = 0.62;
            e.radius_px = radii[r];
            e.angle_deg = angles[a];
            phi_t = atan(-e.light_n / e.light_v);
            want_st = e.radius_px * (1 - cos(phi_t));
            assert_int_equal(fit_shifted(&e, 0.4, &pr), CDSP_OK);
            if (getenv("CDSP_TEST_VERBOSE"))
                print_message("radius %g angle %g: offset %.5f (want -0.4) shadow %.3f (want %.3f) chi2 %.4f\n",
                              radii[r], angles[a], (double)pr.offset, (double)pr.shadow, want_st,
                              (double)pr.fit_chi2);
            if (fabs((double)pr.offset + 0.4) > tol)
                fail_msg("radius %g angle %g: offset %.5f, want -0.4", radii[r], angles[a], (double)pr.offset);
            if (fabs((double)pr.shadow - want_st) > 0.03)
                fail_msg("radius %g angle %g: shadow %.3f, want %.3f", radii[r], angles[a], (double)pr.shadow,
                         want_st);
        }
}

/* A limb in shadow whose terminator is inside the blur zone (optical blur
 * 3 px, terminator 5.03 px from the silhouette at radius 80, light l_n
 * -0.35, l_v 0.94, ambient 0.3; make bench-accuracy's shadowed-limb cells):
 * the area balance cannot place the terminator there (shadow 0) and the
 * forward model without one took the kink for the limb's square root,
 * 0.23-0.35 px off (main before the terminator: 0.23356 px at contrast
 * -10, 0.345 at +10, 16 bit). With the terminator fitted (fwd_terminator)
 * the silhouette is within 1e-3 px and the terminator within 0.05 px of
 * s_t (measured: 1.0e-3 px at worst, row 1 at 45 degrees, terminators
 * within 0.012 px; float alike). Noise-free 16 bit, the line 0.2 px off;
 * rows: contrast 10 and 40 both polarities, angles 0.7, 45, 67.5, and a
 * second light (l_n -0.28: s_t 3.20 px). Tolerance 3e-3 px (3x the
 * worst), the move applied (cdsp_profile_applies). On main row 0 was
 * 0.237 px off and row 3 CDSP_E_NOCONVERGE. */
static void test_shadow_in_blur(void **state)
{
    static const struct {
        double contrast, angle, ln, lv;
        int pol;
    } rows[] = {
        {10, 0.7, -0.35, 0.94, -1}, {10, 45, -0.35, 0.94, 1}, {40, 67.5, -0.35, 0.94, -1},
        {40, 22.5, -0.35, 0.94, 1}, {10, 0.7, -0.28, 0.96, -1}, {40, 45, -0.28, 0.96, 1},
    };
    size_t r;
    (void)state;
    for (r = 0; r < sizeof rows / sizeof rows[0]; r++) {
        sup_edge_spec e;
        cdsp_profile pr;
        cdsp_profile_params pp;
        double want_st;
        sup_edge_spec_default(&e);
        e.bits = 16;
        e.angle_deg = rows[r].angle;
        e.offset_px = 0.3;
        e.ambient = 0.3;
        e.light_n = rows[r].ln;
        e.light_v = rows[r].lv;
        e.blur_px = 3;
        e.background = (rows[r].pol > 0 ? 60 : 60 + rows[r].contrast) * 257;
        e.pipe = (rows[r].pol > 0 ? 60 + rows[r].contrast : 60) * 257;
        want_st = e.radius_px * (1 - cos(atan(-e.light_n / e.light_v)));
        assert_int_equal(fit_shifted(&e, 0.2, &pr), CDSP_OK);
        cdsp_profile_params_default(&pp);
        if (getenv("CDSP_TEST_VERBOSE"))
            print_message("row %zu: offset %+.5f (want -0.2) shadow %.3f (want %.3f) blur %.4f chi2 %.3g applies %d\n",
                          r, (double)pr.offset, (double)pr.shadow, want_st, (double)pr.blur, (double)pr.fit_chi2,
                          cdsp_profile_applies(&pr, &pp, 4));
        if (fabs((double)pr.offset + 0.2) > 3e-3)
            fail_msg("row %zu: offset %.5f, want -0.2", r, (double)pr.offset);
        if (fabs((double)pr.shadow - want_st) > 0.05)
            fail_msg("row %zu: shadow %.3f, want %.3f", r, (double)pr.shadow, want_st);
        if (!cdsp_profile_applies(&pr, &pp, 4))
            fail_msg("row %zu: not applied (fit_chi2 %.3g, flat %d)", r, (double)pr.fit_chi2, pr.flat);
    }
}

/* A faint limb under strong shading (ambient 0.3, front light l_n 0.3,
 * pipe 70 on 60: 10 gray levels at the pipe's middle, the shading darker
 * than the background next to the silhouette; noise-free 16 bit): the
 * area balance's rounds fail there (Newton's G' vanishes or d runs off:
 * CDSP_E_NOCONVERGE on main, the detector's line kept 0.15-1.3 px off,
 * make bench-accuracy's 63 faint-limb cells) and the forward model alone
 * (fwd_alone) places the silhouette: measured within 1.2e-3 px on the
 * study's 16-bit cells; here the line where the detector put it (the
 * study's line offsets): measured 3e-4 to 9e-4 px, double and float.
 * Tolerance 3e-3 px, and the move applied. */
static void test_faint_limb_alone(void **state)
{
    static const struct {
        double blur, motion, motion_deg, angle, shift;
    } rows[] = {
        {0.5, 0, 0, 0.7, 0.154}, {1.5, 0, 0, 22.5, -0.657}, {0.7, 7, 0, 67.5, -1.32}, {0.7, 15, 90, 22.5, -0.023},
    };
    size_t r;
    (void)state;
    for (r = 0; r < sizeof rows / sizeof rows[0]; r++) {
        sup_edge_spec e;
        cdsp_profile pr;
        cdsp_profile_params pp;
        cdsp_status st;
        sup_edge_spec_default(&e);
        e.bits = 16;
        e.angle_deg = rows[r].angle;
        e.offset_px = 0.3;
        e.ambient = 0.3;
        e.light_n = 0.3;
        e.light_v = 0.95;
        e.blur_px = rows[r].blur;
        e.motion_px = rows[r].motion;
        e.motion_deg = rows[r].motion_deg;
        e.background = 60 * 257;
        e.pipe = 70 * 257;
        st = fit_shifted(&e, rows[r].shift, &pr);
        cdsp_profile_params_default(&pp);
        if (getenv("CDSP_TEST_VERBOSE"))
            print_message("row %zu: status %d offset %+.5f (want %+.5f) blur %.4f chi2 %.3g applies %d\n", r, (int)st,
                          (double)pr.offset, -rows[r].shift, (double)pr.blur, (double)pr.fit_chi2,
                          cdsp_profile_applies(&pr, &pp, 4));
        if (st != CDSP_OK)
            fail_msg("row %zu: status %d", r, (int)st);
        if (fabs((double)pr.offset + rows[r].shift) > 3e-3)
            fail_msg("row %zu: offset %.5f, want %.5f", r, (double)pr.offset, -rows[r].shift);
        if (!cdsp_profile_applies(&pr, &pp, 4))
            fail_msg("row %zu: not applied (fit_chi2 %.3g, flat %d)", r, (double)pr.fit_chi2, pr.flat);
    }
}

/* cdsp_profile_applies's rules, on made-up fits (h = 4: the detector's
 * window spans a blur up to (h + 1/2) / 4.66 = 0.966 px). */
static void test_applies(void **state)
{
    static const struct {
        double offset, blur, chi2, shadow;
        int flat, saturated, want;
    } rows[] = {
        {0.30, 0.76, 0.01, 0, 0, 0, 1},  /* a shaded limb: moved */
        {0.30, 0.76, 0.50, 0, 0, 0, 0},  /* does not fit */
        {0.30, 0.76, 0.01, 0, 0, 1, 0},  /* a saturation plateau */
        {0.01, 0.90, 0.01, 0, 1, 0, 0},  /* flat, a blur the window spans */
        {0.01, 1.00, 0.01, 0, 1, 0, 1},  /* flat, a blur it does not */
        {0.01, 0.85, 0.01, 15, 0, 0, 0}, /* flat in shadow over the window */
        {0.01, 0.85, 0.01, 4, 0, 0, 1},  /* a shadow shorter than h + 1/2 */
        {0.01, 0.85, 0.01, 4.7, 0, 0, 0}, /* one beyond it (the paper's p1) */
        {2.10, 0.76, 0.01, 0, 0, 0, 0},  /* a move no blur explains (> 2.02 px) */
        {1.90, 0.76, 0.01, 0, 0, 0, 1},  /* one it does */
        {4.20, 4.40, 0.01, 0, 1, 0, 1},  /* a 15 px motion blur's 4.2 px */
    };
    cdsp_profile_params pp;
    size_t r;
    (void)state;
    cdsp_profile_params_default(&pp);
    for (r = 0; r < sizeof rows / sizeof rows[0]; r++) {
        cdsp_profile pr;
        memset(&pr, 0, sizeof pr);
        pr.offset = (cdsp_real)rows[r].offset;
        pr.blur = (cdsp_real)rows[r].blur;
        pr.fit_chi2 = (cdsp_real)rows[r].chi2;
        pr.shadow = (cdsp_real)rows[r].shadow;
        pr.flat = rows[r].flat;
        pr.saturated = rows[r].saturated;
        if (cdsp_profile_applies(&pr, &pp, 4) != rows[r].want)
            fail_msg("row %zu: applies %d, want %d", r, !rows[r].want, rows[r].want);
    }
}

/* Noise: the reported sigma_offset against the offset's scatter over 64
 * seeds, 8 bit, 2 gray levels of noise, 80 scanlines, on flat edges, lit
 * limbs (the model's case; 0, 5, 17 and 45 degrees), a limb in shadow and
 * blurs wider than the detector's window.
 * sigma_offset propagates the bins' noise through the sides' fits, their
 * extrapolation to the silhouette and the measured blur (area_sigma), over
 * 1 - rho, the rounds' contraction. Before, it held the window's trapezoid
 * sum alone: 0.0035 px on the flat row against a scatter of 0.022 (and
 * without 1 - rho, 0.66-0.70 of the lit limbs' scatter).
 * Two statistics. (1) The ratio estimate / scatter (the mean sigma over the
 * seeds' standard deviation): the scatter of N seeds is itself uncertain by
 * 1 / sqrt(2 (N - 1)), 0.089 at N = 64, so the ratio must lie within 3 of
 * those of 1. (At 45 degrees cdsp_profile_fit's 81 samples 1 px
 * apart along the contour had fallen on 57 scanlines, 24 of them twice,
 * bins not independent: variance sum m^2 / sum m = 129 / 81 times what
 * independent bins give, a ratio of 0.78 measured for 0.79 derived; it
 * samples one point per scanline now.) With the mean offset within 3
 * standard errors of 0 plus 0.002 px (test_lambertian_limb's tolerance
 * for these limbs). (2) The z-scores'
 * RMS, sqrt(mean((offset / sigma_offset)^2)) (the true offset is 0: a bias
 * counts), against 1 within the same tolerance: each seed's sigma
 * must fit its own error, not only on average. Rows whose seeds mix two
 * regimes are judged by (2) alone: the limb in shadow (its terminator
 * found on some seeds) and the blurs of 2 and 3 px, where the forward
 * model (its sigma the fit's covariance, fwd_sigma) replaces the area
 * balance on most seeds and on the others the area balance stays, offsets
 * up to 0.35 px with sigmas up to 0.55 px.
 * Measured, ratio / z RMS, double then float: flat 1.06 / 0.90, 0.93 / 1.06
 * and 1.07 / 0.94, 1.08 / 0.96; lit 1.03 / 0.98, 0.88 / 1.15, 0.96 / 1.05,
 * 0.95 / 1.02 and 0.98 / 0.99, 1.03 / 1.06, 0.96 / 1.06, 1.00 / 1.06; at 45
 * degrees 1.02 / 1.03 and 0.97 / 1.07; shadow z 1.01 and 0.86; blur 2 and
 * 3 px z 1.14, 0.88 and 1.12, 0.94. Three faults these rows caught: the
 * forward model reported its window's part alone (z 1.32 and 2.32 at blur
 * 2 and 3 px); the duplicated scanlines at 45 degrees (above); and rho
 * read from two alternating moves (a cycle between two zones' bins) shrank
 * the sigma of those seeds by up to 1.8 (z 1.34-1.48 on the lit and 5
 * degree flat rows).
 * Left out, as not yet met: a limb in shadow under 2.5 px of blur, 8 bit,
 * z RMS 4.7: its offsets are 1.5-2.5 px off with sigmas of 0.3-0.6, though
 * cdsp_profile_applies refuses all 64 and their bounds, 1.5-14 px, cover
 * them, so the frame path keeps the detector's line; 7 px of motion
 * across, 1.26, from area-balance seeds 0.19-0.7 px off. */
static void test_noise(void **state)
{
    static const struct {
        double angle, ambient, ln, lv, pipe, blur;
        int z_only; /* 1: judged by the z-scores' RMS alone (above) */
    } rows[] = {
        {0, 1, 0, 0, 160, 0.7, 0}, /* flat: the detector's regime */
        {5, 1, 0, 0, 160, 0.7, 0},
        {0, 0.6, 0.3, 0.95, 160, 0.7, 0}, /* lit limbs */
        {5, 0.6, 0.3, 0.95, 160, 0.7, 0},
        {17, 0.6, 0.3, 0.95, 160, 0.7, 0},
        {5, 0.3, 0.7, 0.71, 200, 0.7, 0},
        {45, 0.6, 0.3, 0.95, 160, 0.7, 0},
        {5, 0.4, -0.65, 0.62, 250, 0.7, 1},   /* a limb in shadow (terminator ~20 px in) */
        {5, 0.3, 0.7, 0.71, 200, 2, 1},       /* the forward model (fwd_sigma) */
        {17, 0.3, 0.7, 0.71, 200, 3, 1},
    };
    const int n = 64;
    const double tol = 3 / sqrt(2.0 * (n - 1));
    size_t r;
    (void)state;
    for (r = 0; r < sizeof rows / sizeof rows[0]; r++) {
        int k;
        double sum = 0, sum2 = 0, est = 0, mean, sd, zz = 0, zrms;
        for (k = 0; k < n; k++) {
            sup_edge_spec e;
            cdsp_profile pr;
            sup_edge_spec_default(&e);
            e.angle_deg = rows[r].angle;
            e.ambient = rows[r].ambient;
            e.light_n = rows[r].ln;
            e.light_v = rows[r].lv;
            e.pipe = rows[r].pipe;
            e.blur_px = rows[r].blur;
            e.offset_px = 0.3;
            e.noise = 2;
            e.seed = (uint64_t)(100 + k);
            assert_int_equal(fit_shifted(&e, 0, &pr), CDSP_OK);
            assert_true(pr.sigma_offset > 0);
            sum += (double)pr.offset;
            sum2 += (double)pr.offset * (double)pr.offset;
            est += (double)pr.sigma_offset;
            zz += (double)pr.offset * (double)pr.offset / ((double)pr.sigma_offset * (double)pr.sigma_offset);
        }
        mean = sum / n;
        sd = sqrt((sum2 - n * mean * mean) / (n - 1));
        est /= n;
        zrms = sqrt(zz / n);
        if (getenv("CDSP_TEST_VERBOSE"))
            print_message("noise row %zu: mean %.5f sd %.5f estimate %.5f ratio %.3f z rms %.3f\n", r, mean, sd, est,
                          est / sd, zrms);
        if (!(fabs(zrms - 1) < tol))
            fail_msg("row %zu: offset / sigma_offset RMS %.3f (want 1 +- %.3f)", r, zrms, tol);
        if (rows[r].z_only)
            continue;
        if (!(fabs(mean) < 3 * sd / sqrt((double)n) + 0.002))
            fail_msg("row %zu: mean offset %.5f px, sd %.5f", r, mean, sd);
        if (!(fabs(est / sd - 1) < tol))
            fail_msg("row %zu: sigma_offset %.5f against a scatter of %.5f (ratio %.3f, want 1 +- %.3f)", r, est, sd,
                     est / sd, tol);
    }
}

/* Bad input and frames with nothing to model. */
static void test_errors(void **state)
{
    sup_edge_spec e;
    cdsp_image img;
    double np[2], l[3];
    cdsp_real L[3], ends[2][2] = {{10, 10}, {10, 100}}, pin[2] = {80, 64}, far_end[2][2] = {{2, 10}, {2, 100}};
    cdsp_profile_params pp;
    cdsp_profile pr;
    void *buf;
    (void)state;
    sup_edge_spec_default(&e);
    buf = sup_edge_render(&e, &img, np, l);
    assert_non_null(buf);
    L[0] = (cdsp_real)l[0];
    L[1] = (cdsp_real)l[1];
    L[2] = (cdsp_real)l[2];
    cdsp_profile_params_default(&pp);
    assert_int_equal(cdsp_profile_fit(NULL, L, pin, (const cdsp_real(*)[2])ends, &pp, &pws, &pr), CDSP_E_ARG);
    assert_int_equal(cdsp_profile_fit(&img, L, pin, (const cdsp_real(*)[2])ends, &pp, NULL, &pr), CDSP_E_ARG);
    pp.max_rows = 3;
    assert_int_equal(cdsp_profile_fit(&img, L, pin, (const cdsp_real(*)[2])ends, &pp, &pws, &pr), CDSP_E_ARG);
    cdsp_profile_params_default(&pp);
    pp.max_half_width_px = (cdsp_real)(CDSP_PROFILE_RANGE_PX + 1);
    assert_int_equal(cdsp_profile_fit(&img, L, pin, (const cdsp_real(*)[2])ends, &pp, &pws, &pr), CDSP_E_ARG);
    cdsp_profile_params_default(&pp);
    {
        cdsp_real zero[3] = {0, 0, 1}, nanl[3] = {1, 0, (cdsp_real)NAN};
        assert_int_equal(cdsp_profile_fit(&img, zero, pin, (const cdsp_real(*)[2])ends, &pp, &pws, &pr), CDSP_E_ARG);
        assert_int_equal(cdsp_profile_fit(&img, nanl, pin, (const cdsp_real(*)[2])ends, &pp, &pws, &pr), CDSP_E_ARG);
    }
    /* p_in on the line: no pipe side */
    {
        cdsp_real on[2] = {(cdsp_real)(-(double)L[2] / (double)L[0]), 50};
        if (fabs((double)L[1]) < 1e-12)
            assert_int_not_equal(cdsp_profile_fit(&img, L, on, (const cdsp_real(*)[2])ends, &pp, &pws, &pr), CDSP_OK);
    }
    /* a line along the frame's left border: every window leaves the frame */
    {
        cdsp_real border[3] = {1, 0, -2}, p2[2] = {60, 64};
        assert_int_equal(cdsp_profile_fit(&img, border, p2, (const cdsp_real(*)[2])far_end, &pp, &pws, &pr),
                         CDSP_E_FEW_POINTS);
    }
    free(buf);
    /* a frame without an edge: the model must not report one */
    {
        sup_edge_spec f;
        sup_edge_spec_default(&f);
        f.pipe = f.background;
        buf = sup_edge_render(&f, &img, np, l);
        assert_non_null(buf);
        assert_int_not_equal(cdsp_profile_fit(&img, L, pin, (const cdsp_real(*)[2])ends, &pp, &pws, &pr), CDSP_OK);
        free(buf);
    }
}

/* The frame path: the model is opt-in (default off: no flag, zero
 * fields); switched on, the solve still succeeds and what it reports is
 * sane; a bad max_rows is refused. */
static void test_frame_path(void **state)
{
    static cdsp_frame_ws ws;
    cdsp_camera cam;
    cdsp_scene s;
    cdsp_image img;
    cdsp_params prm;
    cdsp_result r;
    cdsp_rng rng;
    double P[3] = {5, -3, 400}, v[3] = {0.2, 1, 0.2};
    void *buf;
    int k;
    (void)state;
    sup_camera(&cam, 640, 480, 800, -0.2, 0);
    sup_scene(&s, P, v, 8);
    buf = sup_render(&s, &cam, 8, 5, &img);
    assert_non_null(buf);
    cdsp_params_default(&prm);
    cdsp_rng_seed(&rng, 1, 1);
    assert_int_equal(prm.profile.enable, 0);
    assert_int_equal(cdsp_frame_solve(&img, &cam, 8, &prm, NULL, &ws, &rng, &r), CDSP_OK);
    assert_false(r.flags & CDSP_FLAG_PROFILE);
    assert_true(r.edge_offset[0] == 0 && r.edge_offset[1] == 0 && r.edge_blur[0] == 0 && r.edge_blur[1] == 0);
    prm.profile.enable = 1;
    assert_int_equal(cdsp_frame_solve(&img, &cam, 8, &prm, NULL, &ws, &rng, &r), CDSP_OK);
    for (k = 0; k < 2; k++) {
        if (r.edge_blur[k] != 0) /* modelled: blur 0.7 px + footprint, ~0.76 */
            assert_true(r.edge_blur[k] > (cdsp_real)0.5 && r.edge_blur[k] < (cdsp_real)1.5);
        assert_true(fabs((double)r.edge_offset[k]) < 1);
    }
    prm.profile.max_rows = 5000;
    assert_int_equal(cdsp_frame_solve(&img, &cam, 8, &prm, NULL, &ws, &rng, &r), CDSP_E_ARG);
    free(buf);
}

/* The detector's line on an exact limb frame as the frame path gets it
 * (sup_edge_line), the profile fitted along it and its systematic bound; *bias: the line's signed offset from the
 * silhouette at the frame's centre, px. 0 if no line. */
static int detector_bound(const sup_edge_spec *e, double *bias, double *bound, cdsp_profile *pr)
{
    static cdsp_edge pts[4096];
    cdsp_image img;
    cdsp_profile_params pp;
    cdsp_edge_params ep;
    cdsp_line ln;
    double np[2], l[3], c0[2], d;
    size_t m = 0;
    void *buf = sup_edge_render(e, &img, np, l);
    assert_non_null(buf);
    if (!sup_edge_line(e, &img, pts, 4096, &m, &ln)) {
        free(buf);
        return 0;
    }
    c0[0] = (e->width - 1) / 2.0 + e->offset_px * np[0];
    c0[1] = (e->height - 1) / 2.0 + e->offset_px * np[1];
    d = (double)ln.l[0] * c0[0] + (double)ln.l[1] * c0[1] + (double)ln.l[2];
    *bias = sup_edge_u(e, c0[0] - d * (double)ln.l[0], c0[1] - d * (double)ln.l[1]);
    cdsp_profile_params_default(&pp);
    if (sup_edge_profile(e, &img, &ln, np, &pp, &pws, pr) != CDSP_OK)
        pr->rows = 0; /* as the frame path: a model that did not fit has no rows */
    cdsp_edge_params_default(&ep); /* the detector's window, as the frame path passes it */
    *bound = (double)cdsp_profile_bound(pr, &pp, ep.half_window);
    free(buf);
    return 1;
}

/* A short shadow: a limb lit from behind (ambient 0.3, l_n -0.35, l_v
 * 0.94: phi_t 20.4 degrees, s_t = 0.063 R) whose terminator lies just
 * beyond the detector's window, h + 1/2 <= s_t < h + 1 (h = 4; R 75 and
 * 80 px: s_t 4.7 and 5.0 px), optical blur 0.5 px. The detector's
 * pixels reach h + 1/2 from the silhouette, so its line is exact there
 * (measured 0.0001-0.0020 px), while the model's window ends 3.5 sigma
 * before the terminator and its sides' extrapolation moved it 0.001-0.011
 * px off (make bench-accuracy's shadowed-limb cells at s_t 4.94-5.0; the
 * paper's p1 at ambient 0.85, s_t 4.7 px: 0.0023-0.0029 px over three
 * noise seeds against the detector's 0.0004-0.0012). Checked: the line
 * the frame path keeps (the detector's unless cdsp_profile_applies) within
 * 0.004 px (2x the detector's worst), which the move the old threshold
 * (h + 1) made failed on the 10-level rows. */
static void test_short_shadow(void **state)
{
    static const struct {
        double radius, contrast, angle;
        int pol, bits;
    } rows[] = {
        {80, 10, 22.5, -1, 8}, {80, 40, 67.5, -1, 8}, {80, 150, 22.5, -1, 8}, {80, 10, 45, 1, 16},
        {75, 10, 22.5, -1, 8}, {75, 40, 67.5, -1, 8}, {75, 150, 22.5, -1, 8}, {75, 10, 45, 1, 16},
    };
    size_t r;
    (void)state;
    for (r = 0; r < sizeof rows / sizeof rows[0]; r++) {
        sup_edge_spec e;
        cdsp_profile pr;
        cdsp_profile_params pp;
        double bias, bound, kept, st_true, scale = rows[r].bits == 8 ? 1 : 257;
        int app;
        sup_edge_spec_default(&e);
        e.angle_deg = rows[r].angle;
        e.offset_px = 0.3;
        e.ambient = 0.3;
        e.light_n = -0.35;
        e.light_v = 0.94;
        e.radius_px = rows[r].radius;
        e.blur_px = 0.5;
        e.bits = rows[r].bits;
        e.background = (rows[r].pol > 0 ? 60 : 60 + rows[r].contrast) * scale;
        e.pipe = (rows[r].pol > 0 ? 60 + rows[r].contrast : 60) * scale;
        assert_true(detector_bound(&e, &bias, &bound, &pr));
        assert_true(pr.rows > 0);
        cdsp_profile_params_default(&pp);
        app = cdsp_profile_applies(&pr, &pp, 4);
        kept = bias + (app ? (double)pr.offset : 0);
        if (getenv("CDSP_TEST_VERBOSE"))
            print_message("row %zu: shadow %.3f detector %+.5f offset %+.5f applies %d kept %+.5f bound %.4f\n", r,
                          (double)pr.shadow, bias, (double)pr.offset, app, kept, bound);
        /* the terminator where the light leaves the limb, s_t = R (1 - cos
         * phi_t), tan phi_t = -l_n / l_v: 5.026 and 4.711 px; found 0.02-0.10
         * px short (the blurred kink), in the regime s_t >= h + 1/2 */
        st_true = e.radius_px * (1 - cos(atan(-e.light_n / e.light_v)));
        if (!(fabs((double)pr.shadow - st_true) < 0.15 && (double)pr.shadow >= 4.5))
            fail_msg("row %zu: shadow %.3f px, want %.3f +- 0.15 and >= 4.5", r, (double)pr.shadow, st_true);
        if (fabs(kept) > 0.004)
            fail_msg("row %zu: kept line %+.5f px off (detector %+.5f, applies %d)", r, kept, bias, app);
        if (fabs(kept) > bound)
            fail_msg("row %zu: bound %.4f below the error %.5f", r, bound, fabs(kept));
    }
}

/* The profile's scanlines read the frame by its stride, rows and columns,
 * 8 and 16 bit (accumulate steps through the pixels): the same frame with
 * rows padded by 5 pixels of full scale (which any pixel read past a row's
 * end or from a row computed without the stride would bring into the
 * profile) gives a bit-identical fit. Noise of 2 gray levels, so that every
 * pixel counts; angles 0.7 (rows), 30 and 89.3 degrees (columns); a
 * Lambertian limb (ambient 0.3, front light). */
static void test_stride(void **state)
{
    static const double angles[] = {0.7, 30, 89.3};
    int a, k;
    (void)state;
    for (k = 0; k < 2; k++)
        for (a = 0; a < 3; a++) {
            sup_edge_spec e;
            cdsp_image img, pad;
            cdsp_profile p0, p1;
            double np[2], l[3];
            size_t bpp, y;
            unsigned char *buf, *pb;
            if (k)
                spec16(&e);
            else
                sup_edge_spec_default(&e);
            e.angle_deg = angles[a];
            e.noise = k ? 2 * 257 : 2;
            e.ambient = 0.3;
            e.light_n = 0.3;
            e.light_v = 0.95;
            buf = sup_edge_render(&e, &img, np, l);
            assert_non_null(buf);
            bpp = img.bits <= 8 ? 1 : 2;
            pad = img;
            pad.stride = img.stride + 5 * bpp;
            pb = malloc(pad.stride * (size_t)img.height);
            assert_non_null(pb);
            memset(pb, 0xFF, pad.stride * (size_t)img.height);
            for (y = 0; y < (size_t)img.height; y++)
                memcpy(pb + y * pad.stride, buf + y * img.stride, (size_t)img.width * bpp);
            pad.data = pb;
            assert_int_equal(fit_image(&e, &img, np, l, 0.3, &p0), CDSP_OK);
            assert_int_equal(fit_image(&e, &pad, np, l, 0.3, &p1), CDSP_OK);
            assert_true(p0.rows > 16 && p0.rows == p1.rows);
            assert_true(p0.offset == p1.offset && p0.blur == p1.blur && p0.noise == p1.noise);
            assert_true(p0.contrast == p1.contrast && p0.shadow == p1.shadow && p0.fit_chi2 == p1.fit_chi2);
            free(pb);
            free(buf);
        }
}

/* The systematic bound (issue 12), per effect: the detector's line's
 * measured bias must be inside the bound, and the bound within a stated
 * factor of it (where the bias is near 0: at most a stated size). Limb frames as make bench-accuracy's (contrast 100 on 60, front
 * light l_n 0.3 l_v 0.95 where shaded, 22.5 degrees; the flat 8-bit one
 * with 0.5 gray level of noise). Measured in double beside each row (bias
 * px, bound px, their ratio); `most`, the largest bound / |bias| allowed
 * (plus the floor), is 1.3-1.5x the measured ratio; below 0.1 it is the
 * largest bound in px (bias ~0). */
static void test_bound(void **state)
{
    static const struct {
        const char *name;
        int bits;
        double ambient, ln, blur, motion, pipe_scale, vignette, most;
    } rows[] = {
        /* bias ~0 (+0.0002, -0.0004): in the detector's regime the bound
         * is |offset| + its floor F0 + T + FQ / |J| (lib/profile.c), 0.0039
         * and 0.0069 px (before that floor, A0 + A1 blur: 0.018-0.019);
         * float: 0.0039 and 0.0127 (its 8-bit offset +0.0072) */
        {"flat, 16 bit", 16, 1, 0, 0.7, 0, 1, 0, 0.006},
        {"flat, 8 bit", 8, 1, 0, 0.7, 0, 1, 0, 0.016},
        /* +0.480 px, bound 0.582 (1.21): the model fits, |offset| 0.466
         * (+ 0.3 blur sqrt(fit_chi2 0.18), lib/profile.c) */
        {"shaded limb ambient 0.3, 16 bit", 16, 0.3, 0.3, 0.7, 0, 1, 0, 1.3},
        /* +0.480, bound 2.61 (5.4): noise-free 8 bit, the rounding repeats
         * along the contour and the model misfits (fit_chi2 1.06), so the
         * bound is the blur zone's */
        {"shaded limb ambient 0.3, 8 bit", 8, 0.3, 0.3, 0.7, 0, 1, 0, 7},
        /* -0.066, bound 0.107 (1.6) */
        {"optical blur 3, flat, 8 bit", 8, 1, 0, 3, 0, 1, 0, 2},
        /* -0.0076, bound 0.039: its floor at blur 2.16 */
        {"motion blur 7 across, flat, 16 bit", 16, 1, 0, 0.7, 7, 1, 0, 1.5},
        /* +0.215, bound 3.39 (15.7): a plateau, no side model holds */
        {"saturation plateau, 8 bit", 8, 0.3, 0.3, 0.7, 0, 2.2, 0, 20},
        /* +0.477, bound 0.615 (1.29) */
        {"vignetting 30 %, 16 bit", 16, 0.3, 0.3, 0.7, 0, 1, 0.3, 1.5},
    };
    size_t r;
    (void)state;
    for (r = 0; r < sizeof rows / sizeof rows[0]; r++) {
        sup_edge_spec e;
        cdsp_profile pr;
        double bias = 0, bound = 0, floor_px;
        sup_edge_spec_default(&e);
        e.bits = rows[r].bits;
        e.angle_deg = 22.5;
        e.offset_px = 0.3;
        e.background = 60 * (rows[r].bits == 8 ? 1 : 257);
        e.pipe = 160 * (rows[r].bits == 8 ? 1 : 257) * rows[r].pipe_scale;
        e.ambient = rows[r].ambient;
        e.light_n = rows[r].ln;
        e.light_v = rows[r].ambient < 1 ? 0.95 : 1;
        e.blur_px = rows[r].blur;
        e.motion_px = rows[r].motion;
        e.vignette = rows[r].vignette;
        /* 8 bit with a camera's noise (0.5 gray level): noise-free, the
         * rounding repeats along the contour and is no noise */
        e.noise = rows[r].bits == 8 && rows[r].ambient == 1 && rows[r].blur < 1 ? 0.5 : 0;
        e.seed = 3;
        if (!detector_bound(&e, &bias, &bound, &pr))
            fail_msg("%s: no line", rows[r].name);
        floor_px = 0.01 + 0.01 * (double)pr.blur;
        if (getenv("CDSP_TEST_VERBOSE"))
            print_message("%-36s bias %+.4f bound %.4f ratio %.2f (offset %+.4f blur %.3f chi2 %.3g sat %d)\n",
                          rows[r].name, bias, bound, bound / fabs(bias), (double)pr.offset, (double)pr.blur,
                          (double)pr.fit_chi2, pr.saturated);
        if (!(fabs(bias) <= bound))
            fail_msg("%s: bias %.4f outside the bound %.4f", rows[r].name, bias, bound);
        if (rows[r].most < 0.1 ? bound > rows[r].most : bound > rows[r].most * fabs(bias) + floor_px)
            fail_msg("%s: bound %.4f, more than %g x the bias %.4f (+ %.3f)", rows[r].name, bound, rows[r].most,
                     bias, floor_px);
    }
}

/* The bound on the paper's scene in directional light (ambient 0.85, the
 * renderer's light), model off as by default: each contour's bound is the
 * describing one (|offset| + 0.01 + 0.01 blur + 0.3 blur sqrt(fit_chi2),
 * at most ~0.14 px at blur 0.75 and fit_chi2 0.25), not the misfit one
 * (|offset| + 1 + 1.5 blur, > 2 px), and covers the contour's error
 * against the exact silhouette. Before the grouped fit_chi2 p3's lit
 * contour (error 0.012 px, bin-to-bin ripple of a 45-degree contour) had
 * 2.14 px; before the terminator's hysteresis p1's shadowed one (error
 * 0.0008 px, terminator 0.3 px beyond the blur zone at 256 scanlines)
 * 1.90 px. Measured now: 0.033-0.097 px. */
static void test_paper_directional_bound(void **state)
{
    static const int pipes[] = {0, 2};
    static cdsp_frame_ws ws;
    cdsp_camera cam;
    cdsp_rng rng;
    size_t i;
    int k;
    (void)state;
    sup_paper_camera(&cam, 0, 0);
    cdsp_rng_seed(&rng, 3, 3);
    for (i = 0; i < sizeof pipes / sizeof pipes[0]; i++) {
        cdsp_scene s;
        cdsp_image img;
        cdsp_result r;
        cdsp_params prm;
        double P[3], v[3], tl[2][3], pin[2];
        void *px;
        sup_paper_bound_scene(&s, pipes[i], 0.85, P, v);
        px = sup_render(&s, &cam, 8, (uint64_t)(50 + pipes[i]), &img);
        assert_non_null(px);
        assert_true(sup_contour_lines(&cam, P, v, 8, tl, pin));
        cdsp_params_default(&prm);
        assert_int_equal(cdsp_frame_solve(&img, &cam, 8, &prm, NULL, &ws, &rng, &r), CDSP_OK);
        assert_true(r.flags & CDSP_FLAG_BOUND);
        for (k = 0; k < 2; k++) {
            /* the contour's line (the detector's: the model is off) against
             * the nearer exact silhouette, at the line's centroid */
            const cdsp_line *ln = &ws.pairs.lines[r.label[k] - 1];
            double c[2] = {(double)ln->centroid[0], (double)ln->centroid[1]}, err = 1e9;
            int t;
            for (t = 0; t < 2; t++) {
                double dd = tl[t][0] * c[0] + tl[t][1] * c[1] + tl[t][2], f[2] = {c[0] - dd * tl[t][0], c[1] - dd * tl[t][1]};
                double e = (double)ln->l[0] * f[0] + (double)ln->l[1] * f[1] + (double)ln->l[2];
                if (fabs(e) < fabs(err))
                    err = e;
            }
            if (getenv("CDSP_TEST_VERBOSE"))
                print_message("p%d contour %d: error %+.4f px, bound %.4f px\n", pipes[i] + 1, k, err,
                              (double)r.edge_bound[k]);
            if (!(fabs(err) <= (double)r.edge_bound[k]))
                fail_msg("p%d contour %d: error %.4f outside the bound %.4f", pipes[i] + 1, k, err,
                         (double)r.edge_bound[k]);
            if (!((double)r.edge_bound[k] <= 0.2))
                fail_msg("p%d contour %d: bound %.4f px, the misfit's (error %.4f)", pipes[i] + 1, k,
                         (double)r.edge_bound[k], err);
        }
        free(px);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_flat_exact),
        cmocka_unit_test(test_lambertian_limb),
        cmocka_unit_test(test_wide_blur_limb),
        cmocka_unit_test(test_wide_blur_flat),
        cmocka_unit_test(test_shadowed_limb),
        cmocka_unit_test(test_shadow_in_blur),
        cmocka_unit_test(test_faint_limb_alone),
        cmocka_unit_test(test_applies),
        cmocka_unit_test(test_short_shadow),
        cmocka_unit_test(test_noise),
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_frame_path),
        cmocka_unit_test(test_bound),
        cmocka_unit_test(test_stride),
        cmocka_unit_test(test_paper_directional_bound),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
