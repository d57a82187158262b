#include "sim/runner/replay.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <map>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "autonomy/car/car_node.h"
#include "autonomy/car/read_ahead.h"
#include "autonomy/hal/car_can.h"
#include "autonomy/hal/hal.h"
#include "autonomy/hal/json.h"
#include "autonomy/hal/ouster.h"
#include "autonomy/log/mcap.h"
#include "autonomy/stack/stack.h"
#include "sim/runner/files.h"
#include "sim/runner/ini.h"
#include "sim/runner/model.h"
#include "sim/runner/report.h"
#include "sim/runner/scenario.h"
#include "sim/world/track.h"

namespace paddock::runner {
namespace {

using nlohmann::json;

std::string text_of(const std::vector<std::uint8_t>& d) { return std::string(d.begin(), d.end()); }

struct LoggedCommand {
  double steering = 0.0, throttle = 0.0, brake = 0.0, yaw_moment = 0.0;
  std::string as_state;
};

}  // namespace

ReplayResult replay(const std::string& path, const ReplayOptions& o) {
  const auto wall0 = std::chrono::steady_clock::now();
  // the log and what it carries besides its messages
  log::McapReader reader(std::make_unique<log::FileSource>(path));
  std::map<std::string, std::string> files;
  try {
    reader.open();
    // a log of any size replays in bounded memory: its messages chunk by
    // chunk, so no attachment or chunk may be larger than an input may be
    for (const log::AttachmentIndex& a : reader.attachment_indexes()) {
      if (a.data_size > kMaxInputBytes)
        throw UserError(path + ": attachment " + a.name + " of " + std::to_string(a.data_size) + " bytes, more than the " +
                        std::to_string(kMaxInputBytes) + " a replay reads: refused");
    }
    for (const log::ChunkIndex& c : reader.chunk_indexes()) {
      if (c.uncompressed_size > kMaxInputBytes)
        throw UserError(path + ": a chunk of " + std::to_string(c.uncompressed_size) + " bytes, more than the " +
                        std::to_string(kMaxInputBytes) + " a replay holds at once: refused");
    }
    for (const log::Attachment& a : reader.read_attachments()) files[a.name] = text_of(a.data);
  } catch (const log::McapError& e) {
    throw UserError(path + ": " + e.what());
  }
  for (const char* need : {"scenario.ini", "track.csv", "car.dbc"}) {
    if (!files.count(need))
      throw UserError(path + ": no attachment " + need + "; expected a log of `paddock run ... --log`");
  }
  // the scenario as the run resolved it, with the log's own files, the user's
  // changes last. Nothing is written and nothing the log names is read from
  // disk: its attachments stay in memory, named LOG/NAME (in messages too)
  const std::string base = std::filesystem::absolute(path).lexically_normal().string();
  const auto attached = [&base](const std::string& name) { return base + "/" + name; };
  FileTable table;
  std::vector<std::string> overrides;
  for (const auto& [name, key] : {std::pair<std::string, std::string>{"track.csv", "scenario.track"},
                                  {"car.dbc", "hal.dbc"},
                                  {"lidar_metadata.json", "hal.lidar_metadata"}}) {
    if (!files.count(name)) continue;
    table[attached(name)] = files[name];
    overrides.push_back(key + "=" + attached(name));
  }
  overrides.insert(overrides.end(), o.overrides.begin(), o.overrides.end());
  std::vector<IniEntry> entries = parse_ini_text(files["scenario.ini"], attached("scenario.ini"), "");
  // a file the log's scenario names but does not carry is not read
  entries.erase(std::remove_if(entries.begin(), entries.end(),
                               [](const IniEntry& e) { return e.section == "hal" && e.key == "lidar_metadata"; }),
                entries.end());
  const Scenario scenario = load_scenario_entries(std::move(entries), attached("scenario.ini"), overrides, &table);
  const world::TrackModel track = world::build_track(load_track_file(scenario.track_path, &table));
  const SimModel model = compile_model(scenario, track);

  // the car: its decoders, its stack and its watchdogs, as the car binary has them
  car::CarNode node(model.stack, model.mission, scenario.lidar_info, scenario.lidar, *scenario.dbc, scenario.hal.dbc,
                    scenario.car.watchdog);

  // the channels by topic
  enum Kind { kOther, kPackets, kCanRx, kDetections, kCones, kState, kCommand };
  std::map<std::uint16_t, Kind> kind;
  for (const auto& [id, ch] : reader.channels()) {
    const std::string& t = ch.topic;
    kind[id] = t == "/lidar/packets" ? kPackets
               : t == "/can/rx"      ? kCanRx
               : t == "/hal/detections" ? kDetections
               : t == "/hal/cones"   ? kCones
               : t == "/hal/state"   ? kState
               : t == "/stack/command" ? kCommand
                                       : kOther;
  }

  ReplayResult r;
  Profile profile;
  Profile* const timing = o.profile ? &profile : nullptr;
  node.set_profile(timing);
  // the control cycles: where the log has the stack's commands, at their
  // instants (the live run's cycles, on any clock), each compared with its
  // command; else (the stack ran elsewhere) every control period
  bool by_commands = false;
  const std::optional<log::Statistics>& stats = reader.statistics();
  for (const auto& [id, k] : kind) {
    if (k != kCommand) continue;
    if (!stats) {  // no Statistics record: its command channel is taken to have some
      by_commands = true;
      continue;
    }
    const auto n = stats->channel_message_counts.find(id);
    by_commands = by_commands || (n != stats->channel_message_counts.end() && n->second > 0);
  }
  const TimeNs period = model.dt_ns * model.every.control;
  const TimeNs from = o.from ? from_seconds(*o.from) : 0;
  const TimeNs until = o.until ? from_seconds(*o.until) : std::numeric_limits<TimeNs>::max();
  TimeNs tick = (from + period - 1) / period * period;  // the first period cycle at or after --from
  // the control cycle at t: the stack, its command against the live one (if logged)
  const auto cycle = [&](TimeNs t, const LoggedCommand* l) {
    const hal::ActuatorCommand c = node.tick(t);
    ++r.cycles;
    r.final_as_state = hal::to_string(c.as_state);
    if (!l) return;
    ++r.compared;
    const bool same = c.steering_angle == l->steering && c.throttle == l->throttle && c.brake == l->brake &&
                      c.yaw_moment == l->yaw_moment && hal::to_string(c.as_state) == l->as_state;
    if (same) {
      ++r.identical;
    } else if (!r.first_difference) {
      r.first_difference = to_seconds(t);
    }
    r.max_steering_difference = std::max(r.max_steering_difference, std::abs(c.steering_angle - l->steering));
    r.max_throttle_difference = std::max(r.max_throttle_difference, std::abs(c.throttle - l->throttle));
    r.max_brake_difference = std::max(r.max_brake_difference, std::abs(c.brake - l->brake));
    if (hal::to_string(c.as_state) != l->as_state) ++r.as_state_differences;
  };

  try {
    log::ReadOptions ro;
    ro.start = static_cast<std::uint64_t>(from);
    log::McapReader::Messages messages = reader.messages(ro);
    // --threads 2: the log read, and the LiDAR pipeline run, on a second thread
    std::optional<car::ReadAhead> ahead;
    if (o.threads > 1) {
      std::optional<car::AheadSetup> setup;
      if (node.perception() && scenario.lidar_info && scenario.dbc) {
        setup.emplace();
        for (const auto& [id, k] : kind) {
          if (k == kPackets) setup->packet_channels.insert(id);
          if (k == kCanRx) setup->can_channels.insert(id);
        }
        setup->lidar = *scenario.lidar_info;
        setup->layout = scenario.lidar;
        setup->dbc = &*scenario.dbc;
        setup->dbc_source = scenario.hal.dbc;
        setup->perception = node.perception()->params();
      }
      ahead.emplace(std::move(messages), static_cast<std::uint64_t>(until), std::move(setup));
      if (node.perception()) node.perception()->perception().set_ahead(&*ahead);
    }
    log::Message m;
    const auto next = [&] { return ahead ? ahead->next(m) : messages.next(m); };
    if (timing) timing->start();
    while (timed(timing, Stage::Logging, next)) {
      const auto at = static_cast<TimeNs>(m.log_time);
      if (at > until) break;
      // the period's cycles before this message
      if (!by_commands) {
        for (; tick < at; tick += period) cycle(tick, nullptr);
      }
      const Kind k = kind.count(m.channel_id) ? kind[m.channel_id] : kOther;
      switch (k) {
        case kPackets:
          node.lidar_packet(at, m.data, m.size);
          break;
        case kCanRx:
          if (const std::optional<hal::CanFrame> f = hal::from_socketcan(m.data, m.size, at)) {
            node.can_frame(*f);
            ++r.can_frames;
          }
          break;
        case kDetections:
        case kCones:
        case kState: {
          const std::uint64_t bad = node.counters().bad_objects;
          node.object(at, reinterpret_cast<const char*>(m.data), m.size);
          if (node.counters().bad_objects != bad)
            throw UserError(path + ": a message at " + std::to_string(to_seconds(at)) +
                            " s that is no paddock JSON: " + node.last_bad_object());
          ++r.struct_messages;
          break;
        }
        case kCommand: {
          // logged after what the cycle took in: the cycle runs now
          const json j = json::parse(m.data, m.data + m.size);
          const LoggedCommand l{j.at("steering_angle").get<double>(), j.at("throttle").get<double>(),
                                j.at("brake").get<double>(), j.at("yaw_moment").get<double>(),
                                j.at("as_state").get<std::string>()};
          cycle(at, &l);
          break;
        }
        case kOther:
          break;
      }
      r.log_time = to_seconds(at);
    }
    // the period's cycles up to the last message's instant
    if (!by_commands) {
      for (; tick <= from_seconds(r.log_time) && tick <= until; tick += period) cycle(tick, nullptr);
    }
    if (timing) {
      timing->stop();
      r.profile = profile;
    }
    if (ahead) {
      if (node.perception()) node.perception()->perception().set_ahead(nullptr);
      const car::ReadAhead::Counters c = ahead->counters();
      r.scans_ahead = static_cast<long>(c.taken);
      r.scans_not_ahead = static_cast<long>(c.not_ahead + c.mismatched);
    }
  } catch (const log::McapError& e) {
    throw UserError(path + ": " + e.what());
  } catch (const json::exception& e) {
    throw UserError(path + ": a message that is no paddock JSON: " + e.what());
  }
  r.lidar_scans = static_cast<long>(node.counters().lidar.rotations);
  r.watchdog_fault = node.watchdog_fault().value_or("");
  r.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return r;
}

std::string replay_text(const std::string& path, const ReplayResult& r) {
  std::ostringstream o;
  char buf[256];
  o << "replay " << path << "\n";
  std::snprintf(buf, sizeof buf, "  log         %.3f s: %ld LiDAR scans, %ld CAN frames, %ld HAL messages\n",
                r.log_time, r.lidar_scans, r.can_frames, r.struct_messages);
  o << buf;
  std::snprintf(buf, sizeof buf, "  stack       %ld control cycles, final AS state %s\n", r.cycles,
                r.final_as_state.empty() ? "-" : r.final_as_state.c_str());
  o << buf;
  if (r.compared == 0) {
    o << "  commands    none in the log to compare with (the stack ran in the car binary: replay its log)\n";
  } else if (r.compared == r.identical) {
    std::snprintf(buf, sizeof buf, "  commands    %ld compared with the log: all identical, bit for bit\n", r.compared);
    o << buf;
  } else {
    std::snprintf(buf, sizeof buf,
                  "  commands    %ld compared with the log: %ld identical; the first difference at %.3f s\n"
                  "              largest differences: steering %.4f rad, throttle %.4f, brake %.4f; AS state in %ld cycles\n",
                  r.compared, r.identical, r.first_difference.value_or(0.0), r.max_steering_difference,
                  r.max_throttle_difference, r.max_brake_difference, r.as_state_differences);
    o << buf;
  }
  if (!r.watchdog_fault.empty()) o << "  watchdog    " << r.watchdog_fault << "\n";
  if (r.scans_ahead + r.scans_not_ahead > 0) {
    std::snprintf(buf, sizeof buf, "  threads     the LiDAR pipeline of %ld scans ran ahead on the second thread, %ld on the stack's\n",
                  r.scans_ahead, r.scans_not_ahead);
    o << buf;
  }
  std::snprintf(buf, sizeof buf, "  speed       %.1f s of log in %.3f s (%.0fx real time)\n", r.log_time, r.wall_time,
                r.wall_time > 0 ? r.log_time / r.wall_time : 0.0);
  o << buf;
  if (r.profile) o << "\nwhere the wall time went (--profile):\n" << profile_table(*r.profile, r.log_time);
  return o.str();
}

}  // namespace paddock::runner
