#pragma once
// a camera frame its writer lends to readers on other threads (the car's
// log, which JPEG-encodes it on its own thread) without a copy. The writer
// renders into a SharedFrame it owns; a reader holds a FrameLease while it
// reads. Before writing again, the writer asks writable(): while a lease is
// out it takes a new frame instead of waiting (lent() says whether one is).
// A lease's release happens before the writer's next write (release and
// acquire on the count), so the reader never sees a half-written frame.
#include <atomic>
#include <memory>
#include <utility>

#include "autonomy/hal/messages.h"

namespace paddock::hal {

struct SharedFrame {
  CameraFrame frame;
  std::atomic<int> leases{0};
};

// a reader's hold on a SharedFrame: copying it takes another
class FrameLease {
 public:
  FrameLease() = default;
  explicit FrameLease(std::shared_ptr<SharedFrame> f) : f_(std::move(f)) {
    if (f_) f_->leases.fetch_add(1, std::memory_order_relaxed);
  }
  FrameLease(const FrameLease& o) : FrameLease(o.f_) {}
  FrameLease(FrameLease&& o) noexcept : f_(std::move(o.f_)) {}
  FrameLease& operator=(FrameLease o) noexcept {
    std::swap(f_, o.f_);
    return *this;
  }
  ~FrameLease() {
    if (f_) f_->leases.fetch_sub(1, std::memory_order_release);
  }
  const CameraFrame& operator*() const { return f_->frame; }
  const CameraFrame* operator->() const { return &f_->frame; }
  explicit operator bool() const { return f_ != nullptr; }

 private:
  std::shared_ptr<SharedFrame> f_;
};

// whether a lease on f is out (an acquire: after false, what its readers
// did happened before)
inline bool lent(const SharedFrame& f) { return f.leases.load(std::memory_order_acquire) != 0; }

// f itself when no lease is out, else a new frame for it (the old one
// stays with its readers)
inline SharedFrame& writable(std::shared_ptr<SharedFrame>& f) {
  if (!f || lent(*f)) f = std::make_shared<SharedFrame>();
  return *f;
}

}  // namespace paddock::hal
