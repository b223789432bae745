// The device model table. Sources: the vendors' data sheets (SensAble "PHANTOM Premium 1.5 /
// 1.5 High Force" and "PHANTOM Omni" specification sheets; 3D Systems "Touch" specification
// sheet), quoted from their specification tables; every estimate says so. hw/README.md repeats
// the table.
#include "graspsim/hw/device_models.hpp"

#include <array>
#include <stdexcept>

namespace graspsim::hw {

namespace {

constexpr double kMm = 1e-3;   // m per mm

const std::array<DeviceModel, 4> kModels = {{
    {
        "premium-1.5", "Phantom Premium 1.5",
        Vec3{381 * kMm, 191 * kMm, 267 * kMm},   // data sheet: 381 W x 267 H x 191 D mm (x W, y D, z H)
        8.5,              // data sheet: maximum exertable force 8.5 N (1.9 lbf)
        1.4,              // data sheet: continuous exertable force (24 h) 1.4 N (0.3 lbf)
        3.5e3,            // data sheet: stiffness 3.5 N/mm (20 lb/in)
        0.075,            // data sheet: apparent mass at tip < 75 g (0.17 lb); the bound is used
        0.04,             // data sheet: backdrive friction 0.04 N (0.1 oz)
        0.005,            // ESTIMATE: not in the data sheet; small against a hand's 1-4 N s/m
        0.03 * kMm,       // data sheet: nominal position resolution 860 dpi, 0.03 mm
        1000.0,           // OpenHaptics servo loop: 1 kHz (the paper's rt-linux driver ran 3 kHz)
    },
    {
        "premium-1.5-hf", "Phantom Premium 1.5 High Force",
        Vec3{381 * kMm, 191 * kMm, 267 * kMm},   // data sheet: 381 W x 267 H x 191 D mm (x W, y D, z H)
        37.5,             // data sheet: maximum exertable force 37.5 N (8.4 lbf)
        6.2,              // data sheet: continuous exertable force (24 h) 6.2 N (1.4 lbf)
        3.5e3,            // data sheet: stiffness 3.5 N/mm
        0.136,            // data sheet: apparent mass at tip < 136 g (0.3 lb); the bound is used
        0.04,             // data sheet: backdrive friction 0.04 N
        0.005,            // ESTIMATE: as for the Premium 1.5 (same linkage)
        0.03 * kMm,       // data sheet: 860 dpi, 0.03 mm
        1000.0,           // OpenHaptics servo loop: 1 kHz
    },
    {
        "omni", "Phantom Omni",
        Vec3{160 * kMm, 70 * kMm, 120 * kMm},    // data sheet: > 160 W x 120 H x 70 D mm (x W, y D, z H)
        3.3,              // data sheet: maximum exertable force 3.3 N
        0.88,             // data sheet: continuous exertable force (24 h) > 0.88 N
        1.02e3,           // data sheet: X 1.26, Y 2.31, Z 1.02 N/mm; the lowest (Z) is used
        0.045,            // data sheet: inertia (apparent mass at tip) ~ 45 g
        0.26,             // data sheet: backdrive friction < 0.26 N; the bound is used
        0.005,            // ESTIMATE: not in the data sheet
        0.055 * kMm,      // data sheet: nominal position resolution > 450 dpi, ~0.055 mm
        1000.0,           // OpenHaptics servo loop: 1 kHz
    },
    {
        "touch", "Touch",
        Vec3{160 * kMm, 70 * kMm, 120 * kMm},    // data sheet: > 160 W x 120 H x 70 D mm (x W, y D, z H)
        3.3,              // data sheet: maximum exertable force 3.3 N
        0.88,             // data sheet: continuous exertable force (24 h) > 0.88 N
        1.02e3,           // data sheet: X 1.26, Y 2.31, Z 1.02 N/mm; the lowest (Z) is used
        0.045,            // data sheet: apparent mass at tip ~ 45 g
        0.26,             // data sheet: backdrive friction < 0.26 N; the bound is used
        0.005,            // ESTIMATE: not in the data sheet
        0.055 * kMm,      // data sheet: ~ 450 dpi, 0.055 mm
        1000.0,           // OpenHaptics servo loop: 1 kHz
    },
}};

}  // namespace

std::span<const DeviceModel> device_models() { return kModels; }

const DeviceModel& device_model(const std::string& name) {
  for (const DeviceModel& m : kModels)
    if (name == m.key || name == m.name) return m;
  std::string known;
  for (const DeviceModel& m : kModels) {
    if (!known.empty()) known += ", ";
    known += std::string(m.key) + " (\"" + m.name + "\")";
  }
  throw std::invalid_argument("unknown device model \"" + name + "\"; known models: " + known);
}

}  // namespace graspsim::hw
