#!/usr/bin/env python3
"""The sampled planar loop's sensitivity in 60-digit decimal arithmetic: the figures
plant/src/studies/linear/tests.rs holds the exported model against (the standard library only).

config/cosim-10g.toml: one axis m x'' = k_s x + k_i i (m = 11.5 kg, k_s = 4.32e5 N/m,
k_i = 216 N/A), sensor A_s = 25 000 V/m, the PD i_k = -A_a (k_p v_k + k_d (v_k - v_{k-1}) / T)
with its gains as f64 (pd at k_e = 1e6 N/m, xi_e = 0.045 on the loop constants), T = 50 us,
the command applied one tick later and held (zero-order hold). Phi, Gamma by hand
(a = sqrt(k_s/m)): Phi = [[cosh aT, sinh(aT)/a], [a sinh aT, cosh aT]],
Gamma = k_i/m [(cosh aT - 1)/a^2, sinh(aT)/a]; P(z) = A_s [1 0] (zI - Phi)^-1 Gamma z^-1,
C(z) = -A_a (k_p + k_d (1 - z^-1)/T), S = 1/(1 - P C) at z = e^{j 2 pi f T}, f given as f64.
"""
from decimal import Decimal as D, getcontext

getcontext().prec = 60
PI = D("3.14159265358979323846264338327950288419716939937510582097494")
TINY = D(10) ** -70


def exp(x):
    s, t, k = D(1), D(1), 1
    while True:
        t = t * x / k
        k += 1
        if abs(t) < TINY:
            return s
        s += t


def cis(x):
    """cos x + j sin x by the series of e^{jx}."""
    re, im, t, k = D(1), D(0), D(1), 1
    while True:
        t = t * x / k
        if abs(t) < TINY:
            return (re, im)
        r = k % 4
        if r == 0:
            re += t
        elif r == 1:
            im += t
        elif r == 2:
            re -= t
        else:
            im -= t
        k += 1


def mul(a, b):
    return (a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0])


def div(a, b):
    n = b[0] * b[0] + b[1] * b[1]
    return ((a[0] * b[0] + a[1] * b[1]) / n, (a[1] * b[0] - a[0] * b[1]) / n)


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1])


def sensitivity(f_hz, kp, kd, t=D(5e-5), m=D("11.5"), ks=D(432000), ki=D(216), a_s=D(25000), a_a=D(1)):
    a = (ks / m).sqrt()
    ch, sh = (exp(a * t) + exp(-a * t)) / 2, (exp(a * t) - exp(-a * t)) / 2
    phi = [[ch, sh / a], [a * sh, ch]]
    gamma = [ki / m * (ch - 1) / (a * a), ki / m * sh / a]
    z = cis(2 * PI * D(f_hz) * t)
    m00, m01 = sub(z, (phi[0][0], D(0))), (-phi[0][1], D(0))
    m10, m11 = (-phi[1][0], D(0)), sub(z, (phi[1][1], D(0)))
    det = sub(mul(m00, m11), mul(m01, m10))
    x0 = div(sub(mul(m11, (gamma[0], D(0))), mul(m01, (gamma[1], D(0)))), det)
    p = div(mul(x0, (a_s, D(0))), z)
    c = mul((-a_a, D(0)), sub((kp + kd / t, D(0)), mul((kd / t, D(0)), div((D(1), D(0)), z))))
    return div((D(1), D(0)), sub((D(1), D(0)), mul(p, c)))


if __name__ == "__main__":
    kp, kd = D(0.2651851851851852), D(3.265566288171425e-5)
    for f in [1.4654344151399898, 28.87381713684395, 1000.0, 8000.0]:
        s = sensitivity(f, kp, kd)
        print(f"({f!r}, {float(s[0])!r}, {float(s[1])!r}),")
