#pragma once
// Internal: adaptive Gauss-Kronrod (7/15) quadrature used to build and check the tables.
#include <cmath>
#include <initializer_list>

namespace footprint::detail {

// 15-point Kronrod abscissae (non-negative half) and weights, with the weights of the
// embedded 7-point Gauss rule (nodes xgk[1], xgk[3], xgk[5], xgk[7]); QUADPACK values.
inline constexpr double kXgk[8] = {
    0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
    0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
    0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
    0.207784955007898467600689403773245, 0.000000000000000000000000000000000};
inline constexpr double kWgk[8] = {
    0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
    0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
    0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
    0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
inline constexpr double kWg[4] = {
    0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
    0.381830050505118944950369775488975, 0.417959183673469387755102040816327};

/// One Gauss-Kronrod 15 panel on [a, b]: returns the Kronrod estimate, sets `err` to
/// |Kronrod - Gauss|.
template <class F>
double gk15(const F& f, double a, double b, double& err) {
    const double c = 0.5 * (a + b), h = 0.5 * (b - a);
    const double fc = f(c);
    double k = fc * kWgk[7], g = fc * kWg[3];
    for (int i = 0; i < 7; ++i) {
        const double x = h * kXgk[i];
        const double s = f(c - x) + f(c + x);
        k += kWgk[i] * s;
        if (i & 1) g += kWg[i / 2] * s;
    }
    err = std::abs((k - g) * h);
    return k * h;
}

template <class F>
double adaptiveImpl(const F& f, double a, double b, double tol, double whole, double err,
                    int depth) {
    if (err <= tol || depth >= 40 || !(b - a > 1e-300)) return whole;
    const double m = 0.5 * (a + b);
    double el = 0, er = 0;
    const double l = gk15(f, a, m, el), r = gk15(f, m, b, er);
    return adaptiveImpl(f, a, m, 0.5 * tol, l, el, depth + 1) +
           adaptiveImpl(f, m, b, 0.5 * tol, r, er, depth + 1);
}

/// Adaptive GK15 integral of f over [a, b] to absolute tolerance `tol` (a <= b).
template <class F>
double integrate(const F& f, double a, double b, double tol) {
    if (!(b > a)) return 0.0;
    double err = 0;
    const double whole = gk15(f, a, b, err);
    return adaptiveImpl(f, a, b, tol, whole, err, 0);
}

/// Integral over [a, b] split at the given break points (kinks of the integrand).
template <class F>
double integrateSplit(const F& f, double a, double b, std::initializer_list<double> breaks,
                      double tol) {
    if (!(b > a)) return 0.0;
    double pts[8];
    int n = 0;
    pts[n++] = a;
    for (double x : breaks) {
        if (!(x > a && x < b) || n >= 7) continue;
        int i = n++;  // insertion sort (at most 6 points)
        while (i > 1 && pts[i - 1] > x) {
            pts[i] = pts[i - 1];
            --i;
        }
        pts[i] = x;
    }
    pts[n++] = b;
    double sum = 0;
    for (int i = 0; i + 1 < n; ++i) sum += integrate(f, pts[i], pts[i + 1], tol / (n - 1));
    return sum;
}

}  // namespace footprint::detail
