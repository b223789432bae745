// Scripting the HD API test double: configure named devices (what they report, how they fail),
// run the scheduler's callbacks one frame at a time on the test's thread, and look at what the
// backend did (forces written, calls made, rules broken).
#pragma once

#include <array>
#include <string>
#include <vector>

#include <HD/hd.h>

namespace hd_double {

struct FakeDevice {
  // Configuration (set by the test).
  std::string name;                                  // the configured name hdInitDevice takes
  HDerror init_error = HD_SUCCESS;                   // hdInitDevice fails with this if set
  int init_internal = 0;                             // ... and this internal code
  std::array<double, 3> position_mm{0.0, 0.0, 0.0};  // HD_CURRENT_POSITION, mm, HD axes
  std::array<double, 3> gimbal{0.0, 0.0, 0.0};       // HD_CURRENT_GIMBAL_ANGLES, rad
  int buttons = 0;                                   // HD_CURRENT_BUTTONS
  double max_force = 8.5;             // N: HD_NOMINAL_MAX_FORCE
  double max_continuous_force = 1.4;  // N: HD_NOMINAL_MAX_CONTINUOUS_FORCE
  double max_stiffness = 3.5;         // N/mm: HD_NOMINAL_MAX_STIFFNESS
  int update_rate = 1000;             // Hz: HD_UPDATE_RATE (the scheduler's servo rate)
  std::string model = "PHANTOM Premium 1.5";
  HDerror frame_error = HD_SUCCESS;   // raised once at the next hdEndFrame if set
  // State and observations (set by the double).
  HHD handle = HD_INVALID_HANDLE;   // valid while initialised
  bool force_output = false;        // hdEnable(HD_FORCE_OUTPUT) called
  std::array<double, 3> force{0.0, 0.0, 0.0};   // N, HD axes: committed at the last hdEndFrame
  int frames = 0;                               // completed hdBeginFrame/hdEndFrame pairs
};

void reset();                                   // no devices, scheduler stopped, logs empty
FakeDevice& add_device(const std::string& name);   // a configured device
void set_default(const std::string& name);      // the device HD_DEFAULT_DEVICE opens
FakeDevice& device(const std::string& name);    // throws if not configured
int run_frames(int n);   // runs every scheduled async callback n times (priority order);
                         // returns how many callback calls were made
int scheduled_callbacks();                 // async callbacks currently scheduled
bool scheduler_running();
const std::vector<std::string>& init_log();   // names hdInitDevice got ("<default>" for NULL)
const std::vector<std::string>& violations(); // misuses of the API (calls outside a frame, ...)

}  // namespace hd_double
