// Steps 3 to 5 of the paper: the ordered accumulator list (OAL).
//
// Inside the list a line is kept as its unit normal (cos theta, sin theta), theta in
// [0, pi), and rho measured from an origin the caller chooses (the detector uses the image
// centre, so that `rchange` means the same at every angle). Matching and averaging work on
// the normal, so the list needs no trigonometry; theta itself is computed only when a line
// is read off (Line()).
#pragma once

#include <algorithm>
#include <vector>

#include "detector/line.h"

namespace oal {

struct OalEntry {
  double rho_px = 0.0;
  double cos_theta = 1.0;
  double sin_theta = 0.0;
  int weight = 1;   ///< votes (paper: "weighting")
  int count = 0;    ///< borders since the entry was created (paper: "count")
  int borders = 1;  ///< borders that voted for the entry at least once
  int last_border = -1;
  int seed_id = -1;  ///< id of the tracked line that seeded the entry, or -1 (Seed())

  /// The line (rho from the list's origin, theta in [0, pi)).
  LineParams Line() const;
  /// Ordering measure of Eq. 3.
  double Score() const { return weight - 0.5 * count; }
  /// 2 * Score(), exactly, as an integer sort key.
  int DoubleScore() const { return 2 * weight - count; }
};

class OrderedAccumulatorList {
 public:
  /// `angle_change_rad`, `r_change_px`: Eq. 1 and 2. `max_lines`: the culling limit of
  /// step 5. `capacity`: a hard bound on entries (>= max_lines); a vote that matches nothing
  /// while the list is full is dropped, so memory never grows past it.
  OrderedAccumulatorList(double angle_change_rad, double r_change_px, int max_lines, int capacity);

  void Clear() { entries_.clear(); }

  /// Step 3 for one pair-line of border `border`, given as its unit normal (cos, sin) and
  /// rho. The entries are tried best first; the first one within anglechange and rchange
  /// (across the 0/pi wrap) gets the vote and moves to the vote-weighted average of its
  /// parameters and the new ones, weighted by its votes before this one. Otherwise a new
  /// entry with weight 1 and count 0 is appended. Returns the index voted for, or -1 if the
  /// vote was dropped.
  int Vote(double cos_theta, double sin_theta, double rho_px, int border);

  /// Appends an entry for a line expected in this frame (a tracker's previous line): weight
  /// 1 (the seed counts as one prior vote in the averaging), count 0, no border yet, and
  /// `seed_id`, which the entry keeps whatever votes it collects. Call after Clear() and
  /// before the first border. Returns its index, or -1 if the list is full.
  int Seed(double cos_theta, double sin_theta, double rho_px, int seed_id);

  /// Steps 4 and 5 at the end of a border: increment `count` of every entry for which
  /// `counts(entry)` is true, sort by Eq. 3 (stable), then cull from the bottom entries with
  /// weight - count/2 < 0 while more than max_lines remain.
  template <typename CountsPredicate>
  void EndBorder(CountsPredicate counts) {
    for (OalEntry& entry : entries_) {
      if (counts(entry)) ++entry.count;
    }
    SortAndCull();
  }

  /// The entries, best first.
  const std::vector<OalEntry>& entries() const { return entries_; }
  int capacity() const { return capacity_; }

 private:
  void SortAndCull();
  /// Appends a new entry (weight 1, count 0) for the line; the list must not be full.
  OalEntry& Append(double cos_theta, double sin_theta, double rho_px);
  /// Index of the first entry within anglechange and rchange of the line, or -1.
  int FirstMatch(double cos_theta, double sin_theta, double rho_px) const;
  void Mirror(std::size_t i);

  double cos_angle_change_;
  double sin_angle_change_;
  double r_change_px_;
  int max_lines_;
  int capacity_;
  std::vector<OalEntry> entries_;
  // SortAndCull's working memory (capacity reserved).
  struct SortKey {
    int double_score;
    int index;
  };
  std::vector<SortKey> order_;
  std::vector<OalEntry> moved_;
  // The entries' normals and rho in float, in list order (capacity rounded up to whole
  // SIMD blocks): matching, the detector's hottest loop, scans these compact arrays rather
  // than the entries.
  std::vector<float> match_cos_, match_sin_, match_rho_;
};

}  // namespace oal
