// igtl_client_main.cpp - tissue-igtl-client: a scripted stand-in for 3D Slicer or PLUS on
// OpenIGTLink (host/igtl/OPENIGTLINK.md). Presses the frog's back with the probe, sending the
// transform "ProbeToTissue" in millimetres at a fixed rate, and prints the force (SENSOR
// "TissueForce") and the surfaces (POLYDATA "TissueSurface") tissue-host sends back.
//
//   tissue-host run host/scenarios/slicer_frog.toml &
//   tissue-igtl-client --port 18944 --duration 3
#include "igtl_client.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <thread>

namespace {

using tissue::ToolMode;
using tissue::host::DevicePose;

struct Options {
  std::string address = "127.0.0.1";
  int port = 18944;
  double duration_s = 3.0;
  double rate_hz = 1000.0;
  double depth_mm = 3.0;     // below the back's top, z = 36 mm
  std::string save_surface;  // the last surface as a legacy VTK file (what Slicer would show)
};

void usage() {
  std::printf(
      "tissue-igtl-client [--address A] [--port P] [--duration S] [--rate HZ] [--depth MM]\n"
      "Presses the frog's back (x -7 mm, y 0) from 10 mm above to --depth mm into it in the first\n"
      "third of --duration, holds, and prints the force and surfaces tissue-host sends back.\n"
      "--save-surface FILE.vtk writes the last surface received (millimetres) for ParaView or Slicer.\n");
}

bool parse(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string key = argv[i];
    if (key == "--help" || key == "-h") return false;
    if (i + 1 >= argc) {
      std::fprintf(stderr, "tissue-igtl-client: %s needs a value\n", key.c_str());
      return false;
    }
    const char* value = argv[++i];
    char* end = nullptr;
    const double number = std::strtod(value, &end);
    const bool numeric = end != value && *end == '\0';
    if (key == "--address") {
      o.address = value;
    } else if (key == "--save-surface") {
      o.save_surface = value;
    } else if (key == "--port" && numeric && number >= 1 && number <= 65535) {
      o.port = static_cast<int>(number);
    } else if (key == "--duration" && numeric && number > 0 && number < 86400) {
      o.duration_s = number;
    } else if (key == "--rate" && numeric && number >= 1 && number <= 10000) {
      o.rate_hz = number;
    } else if (key == "--depth" && numeric && number >= 0 && number <= 20) {
      o.depth_mm = number;
    } else {
      std::fprintf(stderr, "tissue-igtl-client: bad option or value: %s %s\n", key.c_str(), value);
      return false;
    }
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (!parse(argc, argv, o)) {
    usage();
    return 2;
  }
  try {
    tissue::host::test::IgtlClient client(o.address, o.port, 10.0);
    std::printf("connected to %s:%d\n", o.address.c_str(), o.port);
    const auto start = std::chrono::steady_clock::now();
    const long ticks = static_cast<long>(o.duration_s * o.rate_hz);
    const double press_s = o.duration_s / 3.0;
    std::size_t printed_forces = 0;
    for (long n = 0; n < ticks; ++n) {
      const double t = static_cast<double>(n) / o.rate_hz;
      DevicePose pose;
      pose.mode = ToolMode::probe;
      const double top_m = 0.036, above_m = 0.010;
      pose.position_m = {-0.007, 0.0, top_m + above_m - (above_m + o.depth_mm * 1e-3) * std::min(1.0, t / press_s)};
      client.send_transform("ProbeToTissue", pose);
      if (n % static_cast<long>(std::max(1.0, o.rate_hz / 10.0)) == 0) {
        const auto forces = client.forces();
        if (forces.size() > printed_forces) {
          const auto& f = forces.back().force_n;
          std::printf("t %6.3f s  probe z %6.2f mm  force %+7.3f %+7.3f %+7.3f N  surfaces %zu\n", t,
                      pose.position_m[2] * 1e3, f[0], f[1], f[2], client.surface_count());
          printed_forces = forces.size();
        }
      }
      std::this_thread::sleep_until(start + std::chrono::microseconds(static_cast<long>(1e6 * (t + 1.0 / o.rate_hz))));
    }
    const auto surface = client.last_surface();
    std::printf("received %zu forces and %zu surfaces (the last: %zu points, %zu triangles)\n", client.forces().size(),
                client.surface_count(), surface ? surface->points : 0, surface ? surface->polygons : 0);
    if (!o.save_surface.empty() && surface) {
      std::FILE* out = std::fopen(o.save_surface.c_str(), "w");
      if (out == nullptr) throw std::runtime_error("cannot write " + o.save_surface);
      std::fprintf(out, "# vtk DataFile Version 3.0\nTissueSurface (mm)\nASCII\nDATASET POLYDATA\nPOINTS %zu float\n",
                   surface->point_list.size());
      for (const auto& p : surface->point_list) std::fprintf(out, "%g %g %g\n", p[0], p[1], p[2]);
      std::fprintf(out, "POLYGONS %zu %zu\n", surface->triangles.size(), 4 * surface->triangles.size());
      for (const auto& t : surface->triangles) std::fprintf(out, "3 %u %u %u\n", t[0], t[1], t[2]);
      std::fclose(out);
      std::printf("wrote %s\n", o.save_surface.c_str());
    }
    return client.forces().empty() ? 1 : 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tissue-igtl-client: %s\n", e.what());
    return 1;
  }
}
