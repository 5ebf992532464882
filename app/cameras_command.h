// `oalservo cameras`: the V4L2 cameras of this machine and the modes each offers (format,
// size, rates), as `source:` in a configuration and --camera-mode ask for them.
#pragma once

#include <iosfwd>
#include <string>

namespace oal {

/// Writes the cameras under `dev_dir` and their modes to `out`, or says plainly there is none.
/// Returns how many there are.
int ListCamerasTo(std::ostream& out, const std::string& dev_dir = "/dev");

/// `oalservo cameras [--dev DIR]`; argv[0] is "cameras".
int RunCameras(int argc, char** argv);

}  // namespace oal
