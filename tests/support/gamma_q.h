// The regularised upper incomplete gamma function, for chi-square p-values in the statistical
// tests: P(chi2_k > x) = gamma_q(k / 2, x / 2).
#pragma once

#include <algorithm>
#include <cmath>

namespace canopy::test {

// Q(a, x): the series below a + 1, Lentz's continued fraction above (Numerical Recipes' split).
inline double gamma_q(double a, double x) {
  if (x <= 0) return 1;
  double gln = std::lgamma(a);
  if (x < a + 1) {
    double ap = a, sum = 1 / a, del = sum;
    for (int n = 0; n < 100000; ++n) {
      ap += 1;
      del *= x / ap;
      sum += del;
      if (std::fabs(del) < std::fabs(sum) * 1e-15) break;
    }
    return std::max(0.0, 1 - sum * std::exp(-x + a * std::log(x) - gln));
  }
  double b = x + 1 - a, c = 1e300, d = 1 / b, h = d;
  for (int i = 1; i < 100000; ++i) {
    double an = -i * (i - a);
    b += 2;
    d = an * d + b;
    if (std::fabs(d) < 1e-300) d = 1e-300;
    c = b + an / c;
    if (std::fabs(c) < 1e-300) c = 1e-300;
    d = 1 / d;
    double del = d * c;
    h *= del;
    if (std::fabs(del - 1) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - gln) * h;
}

} // namespace canopy::test
