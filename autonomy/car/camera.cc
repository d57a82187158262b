#include "autonomy/car/camera.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "autonomy/hal/image.h"

namespace paddock::car {
namespace {

int xioctl(int fd, unsigned long request, void* arg) {
  int r;
  do r = ::ioctl(fd, request, arg);
  while (r < 0 && errno == EINTR);
  return r;
}

std::string reason() { return std::strerror(errno); }

}  // namespace

void V4l2Camera::fail(const std::string& what) {
  release();  // a constructor that throws has no destructor run
  throw std::runtime_error(what);
}

V4l2Camera::V4l2Camera(const std::string& device, int width, int height)
    : device_(device), width_(width), height_(height) {
  fd_ = ::open(device.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) throw std::runtime_error("no camera at " + device + ": " + reason() + " (v4l2-ctl --list-devices shows the cameras)");
  v4l2_capability cap{};
  if (xioctl(fd_, VIDIOC_QUERYCAP, &cap) != 0) fail(device + " is no V4L2 camera (VIDIOC_QUERYCAP: " + reason() + ")");
  const std::uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
  if (!(caps & V4L2_CAP_VIDEO_CAPTURE) || !(caps & V4L2_CAP_STREAMING))
    fail(device + " (" + reinterpret_cast<const char*>(cap.card) + ") cannot stream video captures");
  // YUYV, else MJPEG, at the scenario's size
  const std::string size = std::to_string(width) + "x" + std::to_string(height);
  v4l2_format f{};
  for (const std::uint32_t pixel : {V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_MJPEG}) {
    f = v4l2_format{};
    f.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    f.fmt.pix.width = static_cast<std::uint32_t>(width);
    f.fmt.pix.height = static_cast<std::uint32_t>(height);
    f.fmt.pix.pixelformat = pixel;
    f.fmt.pix.field = V4L2_FIELD_NONE;
    if (xioctl(fd_, VIDIOC_S_FMT, &f) != 0) fail(device + ": VIDIOC_S_FMT: " + reason());
    if (f.fmt.pix.pixelformat == pixel && f.fmt.pix.width == static_cast<std::uint32_t>(width) &&
        f.fmt.pix.height == static_cast<std::uint32_t>(height))
      break;
  }
  if (f.fmt.pix.width != static_cast<std::uint32_t>(width) || f.fmt.pix.height != static_cast<std::uint32_t>(height) ||
      (f.fmt.pix.pixelformat != V4L2_PIX_FMT_YUYV && f.fmt.pix.pixelformat != V4L2_PIX_FMT_MJPEG))
    fail(device + " streams neither YUYV nor MJPEG at " + size + " (the scenario's [camera] width and height)");
  mjpeg_ = f.fmt.pix.pixelformat == V4L2_PIX_FMT_MJPEG;
  stride_ = f.fmt.pix.bytesperline > 0 ? f.fmt.pix.bytesperline : 2u * static_cast<std::size_t>(width);
  v4l2_requestbuffers req{};
  req.count = 4;
  req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  req.memory = V4L2_MEMORY_MMAP;
  if (xioctl(fd_, VIDIOC_REQBUFS, &req) != 0 || req.count < 2)
    fail(device + ": no memory-mapped capture buffers (VIDIOC_REQBUFS: " + reason() + ")");
  for (std::uint32_t i = 0; i < req.count; ++i) {
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    b.index = i;
    if (xioctl(fd_, VIDIOC_QUERYBUF, &b) != 0) fail(device + ": VIDIOC_QUERYBUF: " + reason());
    void* p = ::mmap(nullptr, b.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, b.m.offset);
    if (p == MAP_FAILED) fail(device + ": mmap: " + reason());
    buffers_.push_back({p, b.length});
    if (xioctl(fd_, VIDIOC_QBUF, &b) != 0) fail(device + ": VIDIOC_QBUF: " + reason());
  }
  v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (xioctl(fd_, VIDIOC_STREAMON, &type) != 0) fail(device + ": VIDIOC_STREAMON: " + reason());
  streaming_ = true;
}

V4l2Camera::~V4l2Camera() { release(); }

void V4l2Camera::release() {
  if (fd_ < 0) return;
  if (streaming_) {
    v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    xioctl(fd_, VIDIOC_STREAMOFF, &type);
    streaming_ = false;
  }
  for (const Buffer& b : buffers_) ::munmap(b.start, b.length);
  buffers_.clear();
  ::close(fd_);
  fd_ = -1;
}

std::optional<hal::CameraFrame> V4l2Camera::read(TimeNs now, std::vector<std::uint8_t>* jpeg) {
  for (;;) {
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    if (xioctl(fd_, VIDIOC_DQBUF, &b) != 0) {
      if (errno == EAGAIN) return std::nullopt;
      throw std::runtime_error(device_ + ": VIDIOC_DQBUF: " + reason());
    }
    std::optional<hal::CameraFrame> frame;
    const auto* data = static_cast<const std::uint8_t*>(buffers_[b.index].start);
    const std::size_t n = std::min<std::size_t>(b.bytesused, buffers_[b.index].length);
    try {
      if (b.flags & V4L2_BUF_FLAG_ERROR) throw std::invalid_argument("the driver marked it bad");
      if (mjpeg_) {
        frame = hal::decode_jpeg(data, n, now);
        if (jpeg) jpeg->assign(data, data + n);
      } else {
        frame.emplace();
        hal::yuyv_to_rgb(data, n, width_, height_, stride_, *frame);
        frame->stamp = now;
        if (jpeg) jpeg->clear();
      }
      ++frames_;
    } catch (const std::invalid_argument&) {
      ++bad_frames_;
      frame.reset();
    }
    if (xioctl(fd_, VIDIOC_QBUF, &b) != 0) throw std::runtime_error(device_ + ": VIDIOC_QBUF: " + reason());
    if (frame) return frame;
  }
}

}  // namespace paddock::car
