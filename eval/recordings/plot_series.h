// The per-frame values an input's report plots (eval/recordings/report.h) of `oalservo evaluate`.
#pragma once

#include <algorithm>
#include <cstddef>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "eval/recordings/frame_judgement.h"
#include "io/json_io.h"

namespace oal {

/// Per-frame values for the plots (report.h), nulls where a value does not exist. Fewer than
/// 2 x `capacity` frames are kept: at that, every other one is dropped and from then on only
/// every second frame recorded (then every fourth...), so a long input's plots cost bounded
/// memory; frames.jsonl keeps every frame.
struct PlotSeries {
  /// The tracks seen longest get a series, this many.
  static constexpr std::size_t kPlottedTracks = 10;

  struct Track {
    int id = 0;
    double rho_px = 0, theta_deg = 0;
  };
  struct TruthLine {
    int line = 0;
    std::optional<double> offset_px, angle_deg;
  };
  struct Row {
    int frame = 0;
    FrameStatus status = FrameStatus::kUnreadable;
    std::optional<double> held, pose_ok, pose_t_mm, pose_r_deg;
    double decode_us = 0;
    std::optional<double> track_us, pose_us;
    std::vector<Track> tracks;
    std::vector<TruthLine> truth;
  };

  std::vector<Row> rows;
  std::map<int, int> seen;      // frames each track was held, every frame counted
  std::size_t capacity = 2048;  ///< EvaluateOptions::plot_frames
  std::size_t offered = 0, stride = 1;

  void Add(Row row) {
    for (const Track& track : row.tracks) ++seen[track.id];
    if (offered++ % stride != 0) return;
    rows.push_back(std::move(row));
    if (rows.size() < 2 * capacity) return;
    for (std::size_t i = 1; 2 * i < rows.size(); ++i) rows[i] = std::move(rows[2 * i]);
    rows.resize((rows.size() + 1) / 2);
    stride *= 2;
  }

  static Json Optional(const std::optional<double>& value) { return value ? Json(*value) : Json(); }
  template <typename Get>
  Json Column(Get get) const {
    Json column = Json::array();
    for (const Row& row : rows) column.push_back(get(row));
    return column;
  }
  // {"key": [value or null per row]} for `keys`, each row's value from `find(row, key)`.
  template <typename Find>
  Json Keyed(const std::vector<int>& keys, Find find) const {
    Json out = Json::object();
    for (int key : keys)
      out[std::to_string(key)] = Column([&](const Row& r) { return find(r, key); });
    return out;
  }
  Json ToJson() const {
    std::vector<std::pair<int, int>> by_seen(seen.begin(), seen.end());  // (id, frames)
    std::stable_sort(by_seen.begin(), by_seen.end(),
                     [](const auto& a, const auto& b) { return a.second > b.second; });
    std::vector<int> tracks;
    for (std::size_t i = 0; i < by_seen.size() && i < kPlottedTracks; ++i) {
      tracks.push_back(by_seen[i].first);
    }
    std::sort(tracks.begin(), tracks.end());
    std::set<int> truth_lines;
    for (const Row& row : rows) {
      for (const TruthLine& line : row.truth) truth_lines.insert(line.line);
    }
    const std::vector<int> lines(truth_lines.begin(), truth_lines.end());
    const auto track_value = [](double Track::*member) {
      return [member](const Row& row, int id) {
        for (const Track& track : row.tracks) {
          if (track.id == id) return Json(track.*member);
        }
        return Json();
      };
    };
    const auto truth_value = [](std::optional<double> TruthLine::*member) {
      return [member](const Row& row, int line) {
        for (const TruthLine& truth : row.truth) {
          if (truth.line == line) return Optional(truth.*member);
        }
        return Json();
      };
    };
    return Json{{"frame", Column([](const Row& r) { return Json(r.frame); })},
                {"status", Column([](const Row& r) { return Json(static_cast<int>(r.status)); })},
                {"held", Column([](const Row& r) { return Optional(r.held); })},
                {"pose_ok", Column([](const Row& r) { return Optional(r.pose_ok); })},
                {"rho", Keyed(tracks, track_value(&Track::rho_px))},
                {"theta_deg", Keyed(tracks, track_value(&Track::theta_deg))},
                {"offset_px", Keyed(lines, truth_value(&TruthLine::offset_px))},
                {"angle_deg", Keyed(lines, truth_value(&TruthLine::angle_deg))},
                {"pose_t_mm", Column([](const Row& r) { return Optional(r.pose_t_mm); })},
                {"pose_r_deg", Column([](const Row& r) { return Optional(r.pose_r_deg); })}};
  }
  Json TimingJson() const {
    return Json{{"decode_us", Column([](const Row& r) { return Json(r.decode_us); })},
                {"track_us", Column([](const Row& r) { return Optional(r.track_us); })},
                {"pose_us", Column([](const Row& r) { return Optional(r.pose_us); })}};
  }
};

}  // namespace oal
