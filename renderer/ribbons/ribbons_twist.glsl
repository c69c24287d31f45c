// ribbons_twist.glsl — twist lines on a tube (Neuhauser et al., Sec. 4, Eqs. 6-7): k lines
// wound around the tube by the accumulated twist r_n = f * sum h_i l_i. A fragment at
// angle phi around the tube (radians) lies at a = phi - r on the unrolled surface; the
// lines sit at a = 0 mod 2 pi / k. Width: the line is w_r wide measured across itself (in
// units of the tube radius, i.e. radians of arc); measured along phi, at slope
// s = r dr/ds (radius times the twist rate) it is w_u = w_r / cos(atan(s)) = w_r sqrt(1 + s^2)
// (Eq. 7, written without trigonometry). Pure functions; the caller supplies the screen
// derivative fw of a (fwidth, with the 2 pi jump of atan removed) for anti-aliasing.

const float SL_RIBBON_TWO_PI = 6.28318530717958648;

// Width along phi of a line w_r wide across itself, at slope s (Eq. 7).
float sl_ribbon_twist_width(float w_r, float slope)
{
    return w_r * sqrt(1.0 + slope * slope);
}

// How much of a pixel at a (radians, any winding) the k lines of width w (along phi)
// cover, anti-aliased over +-fw; when the period is below a pixel (fw >= half a period)
// the mean cover w k / 2 pi, so fine stripes fade to grey instead of aliasing. k >= 1.
float sl_ribbon_twist_cover(float a, float fw, int k, float w)
{
    float period = SL_RIBBON_TWO_PI / float(k);
    float mean = clamp(w / period, 0.0, 1.0);
    if (!(fw < 0.5 * period))
        return mean;
    float d = abs(a - period * round(a / period)); // distance to the nearest line, in [0, period / 2]
    return 1.0 - smoothstep(0.5 * w - fw, 0.5 * w + fw, d);
}
