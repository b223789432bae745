// What every physics stage does for each body, whichever integrator moves it: its row of the
// record at the start of the step, the pose it stepped from, and after the move the checks that
// stop a blown-up run and count it towards sleep.
#pragma once

#include <cstdint>

#include "graspsim/engine/model.hpp"
#include "graspsim/engine/record.hpp"
#include "graspsim/engine/state.hpp"

namespace graspsim {

// Body b's physics row at this tick: its state, the contact points counted, the grasp fields
// cleared (the grasp rules fill them).
BodyRecord& record_body_state(const State& state, int b, int floor_points, int body_points, TickRecord& record);

// A sleeping body's row: its pose, zero velocity, force and torque; the floor points still active
// and the points of its pairs standing.
void record_sleeping_body(const State& state, int b, int body_points, TickRecord& record);

// The pose before the step (a free finger's path is taken relative to it) and the tick it was taken at.
void mark_stepped(BodyState& bs, std::int64_t tick);

// After a body's step: its finger window cleared, the record flagged if its state diverged
// (non-finite, or faster than kDivergedSpeed / kDivergedAngularSpeed), and, with sleep on, the
// still steps counted and the body put to sleep after enough of them with no finger on it.
void finish_body_step(const Model& model, State& state, int b, TickRecord& record);

}  // namespace graspsim
