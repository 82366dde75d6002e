// Shared by the atmosphere's per-ray tests (AtmosphereRayTest, AtmosphereHorizonTest): one set of small
// tables, computed once per process for each order count.
#pragma once

#include <crep/atmosphere/atmosphere.h>

namespace crep::test {

/// Default parameters, 16x32x16x8, `orders` orders (1 or 2), 64 single and 32 order steps, 64 sphere
/// samples, a 64x256 optical depth table of 256 steps, 16 ambient texels.
inline const AtmosphereTables& smallAtmosphereTables(int orders = 2) {
  static const auto make = [](int n) {
    AtmospherePrecomputeOptions o;
    o.size = {16, 32, 16, 8};
    o.orders = n;
    o.singleSteps = 64;
    o.orderSteps = 32;
    o.sphereSamples = 64;
    o.opticalDepthHeight = 64;
    o.opticalDepthZenith = 256;
    o.opticalDepthSteps = 256;
    o.ambientSize = 16;
    return precomputeAtmosphere(AtmosphereParameters{}, o);
  };
  if (orders == 1) {
    static const AtmosphereTables single = make(1);
    return single;
  }
  static const AtmosphereTables two = make(2);
  return two;
}

} // namespace crep::test
