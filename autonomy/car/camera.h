#pragma once
// the car's camera: a V4L2 capture device (a UVC or GMSL camera's driver),
// streamed by memory-mapped buffers. It streams the scenario's image size in
// YUYV (converted to RGB) or, when the camera has no YUYV at that size, MJPEG
// (decoded; the JPEG bytes kept for the log as they came).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/hal/messages.h"

namespace paddock::car {

class V4l2Camera {
 public:
  // opens `device` and starts streaming width x height; throws
  // std::runtime_error naming the device and what is wrong: no such device,
  // a device that is no V4L2 capture device, neither YUYV nor MJPEG at that
  // size, buffers that cannot be mapped
  V4l2Camera(const std::string& device, int width, int height);
  ~V4l2Camera();
  V4l2Camera(const V4l2Camera&) = delete;
  V4l2Camera& operator=(const V4l2Camera&) = delete;

  int fd() const { return fd_; }
  const char* format() const { return mjpeg_ ? "MJPEG" : "YUYV"; }
  // the next captured frame if one is waiting, stamped `now` (its receive
  // time); jpeg: the camera's own JPEG bytes (MJPEG), else left empty. A
  // frame the driver marks as bad, or a JPEG that does not decode, is
  // skipped and counted
  std::optional<hal::CameraFrame> read(TimeNs now, std::vector<std::uint8_t>* jpeg = nullptr);
  std::uint64_t frames() const { return frames_; }
  std::uint64_t bad_frames() const { return bad_frames_; }

 private:
  struct Buffer {
    void* start = nullptr;
    std::size_t length = 0;
  };
  [[noreturn]] void fail(const std::string& what);
  void release();  // stops the stream, unmaps the buffers, closes the device

  std::string device_;
  int fd_ = -1;
  int width_ = 0, height_ = 0;
  std::size_t stride_ = 0;
  bool mjpeg_ = false;
  bool streaming_ = false;
  std::vector<Buffer> buffers_;
  std::uint64_t frames_ = 0, bad_frames_ = 0;
};

}  // namespace paddock::car
