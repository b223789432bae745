// The scale scenes (tools/bench/README.md, "Scale"): n boxes on a floor in one of five layouts,
// as plain poses, so that graspsim's benchmark and tests and the peer engines' benchmark
// (tools/bench/peers) build exactly the same scene. Header-only, no engine types: a box is its
// centre and a yaw about the vertical.
//
// Every box is a cube of side `kSide` (m) and mass `kMass` (kg), friction `kMu` against the floor
// and each other, no restitution; gravity -9.81 m/s^2 along z; the floor is the plane z = 0.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace graspsim::bench::scale {

inline constexpr double kSide = 0.1;    // m: cube side
inline constexpr double kMass = 1.0;    // kg
inline constexpr double kMu = 0.6;      // 1: friction, box on floor and box on box
inline constexpr double kGravity = 9.81;   // m/s^2, along -z

enum class Layout {
  kApart,     // a square grid on the floor, 0.3 m between centres: n islands of one box
  kIsland,    // a square grid on the floor, side by side, touching (+ gap): one island
  kTower,     // one column, each box on the one below, touching (+ gap)
  kPyramid,   // a 2-D pyramid (rows of n_row, n_row - 1, ..., 1 boxes), each box on two below;
              // n is rounded down to a triangular number r (r + 1) / 2
  kPile,      // boxes dropped in columns on an 18 cm grid, 12 cm apart up a column, at most 10
              // a column (the top ~1.2 m up), each offset by up to 2 cm and turned by up to
              // 0.3 rad (a fixed generator), so that they land askew and topple into a pile.
              // None overlaps at the start: a 10 cm box turned 0.3 rad spans 0.05 (cos + sin)
              // = 6.4 cm from its centre, 8.4 cm with its offset, under half of 18 cm
};

inline const char* layout_name(Layout l) {
  switch (l) {
    case Layout::kApart: return "apart";
    case Layout::kIsland: return "island";
    case Layout::kTower: return "tower";
    case Layout::kPyramid: return "pyramid";
    case Layout::kPile: return "pile";
  }
  return "?";
}

inline bool parse_layout(const std::string& s, Layout& out) {
  for (Layout l : {Layout::kApart, Layout::kIsland, Layout::kTower, Layout::kPyramid, Layout::kPile}) {
    if (s == layout_name(l)) {
      out = l;
      return true;
    }
  }
  return false;
}

struct BoxPose {
  double x, y, z;   // m: centre
  double yaw;       // rad: about +z
};

// Rows of a pyramid of at most n boxes: the largest r with r (r + 1) / 2 <= n (at least 1).
inline int pyramid_rows(int n) {
  int r = 1;
  while ((r + 1) * (r + 2) / 2 <= n) ++r;
  return r;
}

// The boxes of a layout. `gap` (m) is left between boxes that touch in the layout (island,
// tower, pyramid; 0: exactly touching, the lowest box exactly on the floor); apart and pile
// ignore it. Deterministic: the pile's offsets come from a 64-bit LCG seeded by `seed`.
inline std::vector<BoxPose> layout_boxes(Layout layout, int n, double gap = 0.0, std::uint64_t seed = 1) {
  std::vector<BoxPose> boxes;
  const double s = kSide, half = 0.5 * kSide;
  const int columns = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
  switch (layout) {
    case Layout::kApart:
    case Layout::kIsland: {
      const double pitch = layout == Layout::kApart ? 0.3 : s + gap;   // m between centres
      for (int i = 0; i < n; ++i) {
        const int row = i / columns, col = i % columns;
        boxes.push_back({(col - 0.5 * (columns - 1)) * pitch, (row - 0.5 * (columns - 1)) * pitch, half, 0.0});
      }
      break;
    }
    case Layout::kTower:
      for (int i = 0; i < n; ++i) boxes.push_back({0.0, 0.0, half + i * (s + gap), 0.0});
      break;
    case Layout::kPyramid: {
      const int rows = pyramid_rows(n);
      const double pitch = s + gap;
      for (int row = 0; row < rows; ++row) {
        const int count = rows - row;
        for (int k = 0; k < count; ++k)
          boxes.push_back({(k - 0.5 * (count - 1)) * pitch, 0.0, half + row * (s + gap), 0.0});
      }
      break;
    }
    case Layout::kPile: {
      std::uint64_t state = seed;
      const auto uniform = [&state] {   // in [-1, 1): Knuth's MMIX LCG, top 53 bits
        state = state * 6364136223846793005ULL + 1442695040888963407ULL;
        return static_cast<double>(state >> 11) * (2.0 / 9007199254740992.0) - 1.0;
      };
      const int side = static_cast<int>(std::ceil(std::sqrt(std::ceil(n / 10.0))));   // columns a side
      for (int i = 0; i < n; ++i) {
        const int column = i % (side * side), level = i / (side * side);
        const double cx = (column % side - 0.5 * (side - 1)) * 0.18, cy = (column / side - 0.5 * (side - 1)) * 0.18;
        const double dx = 0.02 * uniform(), dy = 0.02 * uniform(), yaw = 0.3 * uniform();
        boxes.push_back({cx + dx, cy + dy, half + 0.01 + 0.12 * level, yaw});
      }
      break;
    }
  }
  return boxes;
}

// J of a solid cube about any axis through its centre: m s^2 / 6 (kg m^2).
inline double cube_inertia() { return kMass * kSide * kSide / 6.0; }

}  // namespace graspsim::bench::scale
