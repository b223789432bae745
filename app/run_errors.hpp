// Why a run stops, said for the user: what happened, where (time and tick), and what to do.
#pragma once

#include <cstdint>
#include <string>

#include "app/pacer.hpp"
#include "graspsim/engine/energy.hpp"
#include "graspsim/engine/simulation.hpp"

namespace graspsim::app {

// Bodies nothing powers gained energy (engine/energy.hpp): which, how much, since when.
std::string energy_gain_message(const Model& model, const EnergyGain& g, double t, std::int64_t tick);
// record.diverged_body left the speed limits at tick n (engine/simulation.hpp).
std::string divergence_message(const Model& model, const State& state, int body, double t, std::int64_t tick);
// A paced tick stalled or fell behind (pace.stalled or pace.lagging): every device was released.
std::string pacing_message(const TickPace& pace, const Pacer& pacer, std::int64_t tick, int rate_servo);
// "interrupted [by SIGTERM] at t = T s" (signal 0: not known).
std::string interrupted_message(int signal, double t);

}  // namespace graspsim::app
