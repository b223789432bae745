// `graspsim replay TRACE.h5`: reruns a trace's scenario with its fingers fed from the recorded
// device samples, and says whether the result is the recording bit for bit.
#pragma once

#include <atomic>
#include <string>
#include <vector>

namespace graspsim::cli {

// args: what follows "replay". Exit codes: 0 reproduced (or, with --set, ran) and every
// expectation held, 1 an expectation failed or a plain replay differs from the recording,
// 2 bad input, 3 the trace could not be written to its end, 128 + `signal` interrupted
// (`interrupt` set).
int replay_command(const std::vector<std::string>& args, const std::atomic<bool>* interrupt,
                   const std::atomic<int>* signal = nullptr);

}  // namespace graspsim::cli
