"""Chebyshev coefficients of the scaled complementary error function used by
:func:`dcee.numeric._verfc` (issue 17): (y + K) · erfcx(y) on y ∈ [0, ∞) as a Chebyshev series
in t = (y − K)/(y + K) ∈ [−1, 1), K = 3, interpolated at 25 Chebyshev nodes from
``scipy.special.erfcx``. Prints the coefficients, the same polynomial in powers of t (what the
kernel evaluates by Horner's rule, ``_ERFCX_POWERS``) and the largest relative error of the
series against scipy on y ∈ [0, 1e6]. Run: .venv/bin/python studies/fit_erfcx.py
"""

import numpy as np
from numpy.polynomial import chebyshev
from scipy.special import erfcx

K = 3.0
DEGREE = 24

nodes = np.cos(np.pi * (np.arange(DEGREE + 1) + 0.5) / (DEGREE + 1))
y = K * (1 + nodes) / (1 - nodes)
coef = chebyshev.chebfit(nodes, erfcx(y) * (y + K), DEGREE)
check = np.concatenate([np.linspace(0, 10, 20001), np.geomspace(10, 1e6, 2000)])
approx = chebyshev.chebval((check - K) / (check + K), coef) / (check + K)
print("_ERFCX_CHEB = (")
for c in coef:
    print(f"    {float(c)!r},")
print(")")
print("_ERFCX_POWERS = (")
for c in chebyshev.cheb2poly(coef):
    print(f"    {float(c)!r},")
print(")")
print(f"# max relative error against scipy: {np.max(np.abs(approx / erfcx(check) - 1)):.2e}")
