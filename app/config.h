// oalservo's YAML configuration. Only the app reads YAML: this file fills the libraries'
// Options structs and rejects what it does not understand, naming the file, the line and
// the key (config/detector.yaml documents every key).
//
//   detector:            # oal::DetectorOptions; keys are exactly its field names
//     paper: true        # start from DetectorOptions::Paper() instead of the defaults
//     step_px: 5
//
//   target: {name: four-line}   # a shipped target (scene/scene.h TargetByName), or in full:
//   target:              # oal::LineTarget (config/four-line-target.yaml documents the keys)
//     name: my-board     # required
//     board_width_m: 0.4 # required, > 0; the board is centred on the object origin
//     board_height_m: 0.3
//     board_grey: 215    # optional, [0, 255]
//     line_grey: 35      # optional, [0, 255]
//     lines:             # required, may be empty; metres on the board plane (x right, y down)
//       - {from: [-0.08, -0.15], to: [-0.08, 0.15], width: 0.03}
//
// A target section replaces the whole target (it never modifies the base's target).
//
//   pose:                # oal::PoseOptions' tunables (config/pose.yaml documents the keys);
//     max_residual_px: 2.0   # the camera, lines_undistorted and the image size come from the
//                            # command (--camera, the detector, the frame), not from here
//
// Sections reserved for later versions (camera, servo, robot, render) are rejected
// with a message saying so, rather than silently ignored.
#pragma once

#include <string>

#include "detector/options.h"
#include "scene/scene.h"
#include "servo/pose.h"

namespace oal {

/// Everything a configuration file can set. A new section is a member here plus one row in
/// config.cpp's section table.
struct AppConfig {
  DetectorOptions detector;
  LineTarget target = FourLineTarget();  ///< the planar target (pose, render, `oalservo target`)
  PoseOptions pose;  ///< `pose:`; its camera, lines_undistorted and image size stay as given
};

/// Applies the YAML file at `path` to `base` and checks the result. Throws
/// std::runtime_error "FILE:LINE: ..." for a missing or malformed file, an unknown section
/// or key, a value of the wrong type, and a value that fails the Options' Check().
AppConfig LoadConfig(const std::string& path, const AppConfig& base = AppConfig());

/// As LoadConfig, from YAML text; `file_name` stands for the file in messages.
AppConfig ParseConfig(const std::string& yaml_text, const std::string& file_name,
                      const AppConfig& base = AppConfig());

}  // namespace oal
