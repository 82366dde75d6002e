// The small atmosphere tables of the GPU tests (8 x 16 x 8 x 4, short marches): a CreateInfo to compute them
// on any backend in well under a second on llvmpipe or lavapipe.
#pragma once

#include <crep/atmosphere/gpu_tables.h>

namespace crep::test {

/// The tests' small tables with `orders` scattering orders, on `backend` (null: a GL backend of its own).
inline AtmosphereTablesPass::CreateInfo smallAtmosphereTables(int orders, gpu::Backend* backend = nullptr) {
  AtmosphereTablesPass::CreateInfo info;
  info.options.size = {8, 16, 8, 4};
  info.options.orders = orders;
  info.options.singleSteps = 32;
  info.options.orderSteps = 32;
  info.options.sphereSamples = 32;
  info.options.opticalDepthHeight = 32;
  info.options.opticalDepthZenith = 64;
  info.options.opticalDepthSteps = 64;
  info.options.ambientSize = 16;
  info.backend = backend;
  return info;
}

} // namespace crep::test
