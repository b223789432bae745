// The triple buffer (live_channel.hpp). The exchanges are acq_rel: the writer's release orders
// its writes to the slot before the slot becomes the waiting one; the reader's acquire orders its
// reads of the slot it took after those writes. A slot is owned by one side at a time.
#include "app/live_channel.hpp"

namespace graspsim::app {

LiveChannel::LiveChannel(std::size_t bodies, std::size_t fingers) {
  for (LiveSnapshot& s : slots_) {
    s.bodies.assign(bodies, LiveBody{});
    s.fingers.assign(fingers, LiveFinger{});
  }
}

void LiveChannel::publish() {
  back_ = middle_.exchange(back_ | kFresh, std::memory_order_acq_rel) & kIndex;
}

const LiveSnapshot* LiveChannel::take() {
  if ((middle_.load(std::memory_order_relaxed) & kFresh) == 0) return nullptr;
  front_ = middle_.exchange(front_, std::memory_order_acq_rel) & kIndex;
  return &slots_[front_];
}

}  // namespace graspsim::app
