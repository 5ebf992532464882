// `oalservo servo-accuracy`: the servo loop from many random start poses, for each law
// (app/servo_accuracy.h); prints a Markdown table and writes the runs as JSON.
#pragma once

namespace oal {

int RunServoAccuracy(int argc, char** argv);

}  // namespace oal
