#pragma once
// The rigcal executable's exit codes (listed in `rigcal --help`).
namespace rigcal::app {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;       // the job ran but failed (e.g. calibration did not converge)
inline constexpr int kExitUsage = 2;         // bad command line
inline constexpr int kExitConfig = 3;        // bad rig config or parameter
inline constexpr int kExitInput = 4;         // unreadable input: missing file, bad capture or metadata
inline constexpr int kExitNotEnoughData = 5; // ran to the end without enough data for a result
inline constexpr int kExitUnverified = 6;    // a result beats the guess but its evidence does not confirm it
inline constexpr int kExitInterrupted = 130; // stopped by a signal before a result

inline constexpr const char* kExitCodesHelp =
    "Exit codes: 0 ok, 1 failed, 2 usage error, 3 config error, 4 input error, "
    "5 not enough data, 6 result unverified, 130 interrupted.";

}  // namespace rigcal::app
