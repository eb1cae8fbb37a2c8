// udp_sender_main.cpp - tissue-udp-sender: a scripted stand-in for a haptic device driver.
//
// Sends a circle or a poke as pose packets to a UdpDevice (tissue-host) at a fixed rate on
// absolute deadlines, and prints the force packets it gets back. Read it as the skeleton of a
// real driver: replace scripted_pose() by the device's measured pose (converted to metres and
// the scene frame), and render the received force on the device instead of printing it.
//
//   tissue-udp-sender --port 47001 --script circle --rate 1000 --duration 5
#include "udp_sender.hpp"

#include <time.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using tissue::host::DevicePose;
using tissue::ToolMode;
namespace udp = tissue::host::udp;

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int /*signal*/) { g_stop = 1; }

struct Options {
  std::string address = "127.0.0.1";
  std::uint16_t port = udp::DEFAULT_PORT;
  std::string script = "circle";
  double rate_hz = 1000.0;
  double duration_s = 5.0;
  std::array<double, 3> centre_m{0.0, 0.0, 0.0};
  double radius_m = 0.02;
  double depth_m = 0.01;
  double period_s = 2.0;
  ToolMode mode = ToolMode::probe;
  long print_every = 100;
};

void usage() {
  std::printf(
      "usage: tissue-udp-sender [options]\n"
      "  --address A      device (tissue-host) address, numeric (default 127.0.0.1)\n"
      "  --port N         device port (default %u)\n"
      "  --script S       circle (in the xy plane around the centre) or poke (down -z and back)\n"
      "  --rate HZ        pose packets per second (default 1000)\n"
      "  --duration S     seconds to run (default 5; Ctrl-C stops early)\n"
      "  --centre X,Y,Z   script centre [m] (default 0,0,0)\n"
      "  --radius M       circle radius [m] (default 0.02)\n"
      "  --depth M        poke depth [m] (default 0.01)\n"
      "  --period S       one circle or one poke [s] (default 2)\n"
      "  --mode M         none, probe or scalpel (default probe)\n"
      "  --print-every N  print one line every N ticks (default 100; 0: summary only)\n",
      static_cast<unsigned>(udp::DEFAULT_PORT));
}

double parse_number(const char* option, const char* text) {
  char* end = nullptr;
  const double value = std::strtod(text, &end);
  if (end == text || *end != '\0' || !std::isfinite(value)) {
    throw std::invalid_argument(std::string(option) + ": not a number: " + text);
  }
  return value;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      usage();
      std::exit(0);
    }
    if (i + 1 >= argc) throw std::invalid_argument(arg + ": missing value (or unknown option)");
    const char* value = argv[++i];
    if (arg == "--address") {
      o.address = value;
    } else if (arg == "--port") {
      const double port = parse_number("--port", value);
      if (port < 1 || port > 65535 || port != std::floor(port)) throw std::invalid_argument("--port: 1..65535");
      o.port = static_cast<std::uint16_t>(port);
    } else if (arg == "--script") {
      o.script = value;
      if (o.script != "circle" && o.script != "poke") throw std::invalid_argument("--script: circle or poke");
    } else if (arg == "--rate") {
      o.rate_hz = parse_number("--rate", value);
      if (o.rate_hz <= 0.0 || o.rate_hz > 10000.0) throw std::invalid_argument("--rate: (0, 10000] Hz");
    } else if (arg == "--duration") {
      o.duration_s = parse_number("--duration", value);
    } else if (arg == "--centre" || arg == "--center") {
      std::string text = value;
      for (double& c : o.centre_m) {
        const std::size_t comma = text.find(',');
        c = parse_number("--centre", text.substr(0, comma).c_str());
        text = comma == std::string::npos ? "" : text.substr(comma + 1);
      }
    } else if (arg == "--radius") {
      o.radius_m = parse_number("--radius", value);
    } else if (arg == "--depth") {
      o.depth_m = parse_number("--depth", value);
    } else if (arg == "--period") {
      o.period_s = parse_number("--period", value);
      if (o.period_s <= 0.0) throw std::invalid_argument("--period: > 0");
    } else if (arg == "--mode") {
      const std::string mode = value;
      if (mode == "none") {
        o.mode = ToolMode::none;
      } else if (mode == "probe") {
        o.mode = ToolMode::probe;
      } else if (mode == "scalpel") {
        o.mode = ToolMode::scalpel;
      } else {
        throw std::invalid_argument("--mode: none, probe or scalpel");
      }
    } else if (arg == "--print-every") {
      o.print_every = static_cast<long>(parse_number("--print-every", value));
    } else {
      throw std::invalid_argument("unknown option " + arg);
    }
  }
  return o;
}

// What a real driver would read from its device.
DevicePose scripted_pose(const Options& o, double t_s) {
  const double phase = 2.0 * std::numbers::pi * t_s / o.period_s;
  DevicePose pose;
  pose.mode = o.mode;
  pose.position_m = o.centre_m;
  if (o.script == "circle") {
    pose.position_m[0] += o.radius_m * std::cos(phase);
    pose.position_m[1] += o.radius_m * std::sin(phase);
  } else {
    pose.position_m[2] -= o.depth_m * 0.5 * (1.0 - std::cos(phase));  // smooth down and back up
  }
  return pose;
}

timespec to_timespec(double t_s) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(std::floor(t_s));
  ts.tv_nsec = static_cast<long>((t_s - std::floor(t_s)) * 1e9);
  return ts;
}

double percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

int run(const Options& o) {
  tissue::host::test::UdpSender sender(o.address, o.port,
                                       o.address.find(':') == std::string::npos ? "127.0.0.1" : "::1");
  std::printf("tissue-udp-sender: %s to %s:%u at %.0f Hz for %.1f s (from local port %u)\n", o.script.c_str(),
              o.address.c_str(), static_cast<unsigned>(o.port), o.rate_hz, o.duration_s,
              static_cast<unsigned>(sender.local_port()));

  // Send time of each recent sequence, to turn a force packet's ack_sequence into a round trip.
  constexpr std::size_t HISTORY = 4096;
  std::vector<double> sent_at(HISTORY, 0.0);
  std::vector<double> round_trips_s;
  std::vector<udp::ForcePacket> forces;
  std::optional<udp::ForcePacket> latest;
  std::uint64_t received = 0, late_ticks = 0;
  double max_force_n = 0.0;

  const double period_s = 1.0 / o.rate_hz;
  const double start_s = tissue::host::test::monotonic_time_s();
  for (long tick = 0; g_stop == 0; ++tick) {
    const double deadline_s = start_s + static_cast<double>(tick) * period_s;
    if (deadline_s - start_s > o.duration_s) break;
    const timespec wake = to_timespec(deadline_s);
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &wake, nullptr);
    const double now_s = tissue::host::test::monotonic_time_s();
    if (now_s - deadline_s > period_s) ++late_ticks;

    const DevicePose pose = scripted_pose(o, now_s - start_s);
    const std::uint64_t sequence = sender.send_pose(pose, now_s);
    sent_at[sequence % HISTORY] = now_s;

    forces.clear();
    sender.drain_forces(forces);
    for (const udp::ForcePacket& f : forces) {
      ++received;
      if (f.ack_sequence != 0 && sequence - f.ack_sequence < HISTORY) {
        round_trips_s.push_back(tissue::host::test::monotonic_time_s() - sent_at[f.ack_sequence % HISTORY]);
      }
      max_force_n = std::max(max_force_n, std::hypot(f.force_n[0], f.force_n[1], f.force_n[2]));
      latest = f;  // a driver renders the newest force (packets carry increasing sequences)
    }
    if (o.print_every > 0 && tick % o.print_every == 0) {
      std::printf("t=%7.3f s  seq=%-7llu pos=(% .4f % .4f % .4f) m", now_s - start_s,
                  static_cast<unsigned long long>(sequence), pose.position_m[0], pose.position_m[1],
                  pose.position_m[2]);
      if (latest) {
        std::printf("  force=(% .3f % .3f % .3f) N  scale=%.2f  ack=%llu", latest->force_n[0], latest->force_n[1],
                    latest->force_n[2], latest->watchdog_scale, static_cast<unsigned long long>(latest->ack_sequence));
      } else {
        std::printf("  (no force packet yet)");
      }
      std::printf("\n");
    }
  }
  std::printf(
      "sent %llu poses; received %llu force packets (%llu malformed); max |force| %.3f N; round trip p50 %.3f ms, "
      "max %.3f ms; late ticks %llu\n",
      static_cast<unsigned long long>(sender.next_sequence() - 1), static_cast<unsigned long long>(received),
      static_cast<unsigned long long>(sender.malformed_forces()), max_force_n, 1e3 * percentile(round_trips_s, 0.5),
      1e3 * percentile(round_trips_s, 1.0), static_cast<unsigned long long>(late_ticks));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  try {
    return run(parse(argc, argv));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tissue-udp-sender: %s\n", e.what());
    return 2;
  }
}
