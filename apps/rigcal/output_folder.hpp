#pragma once
// The --out folder of a command: created and proven writable before any work starts (a read-only or
// impossible folder is a one-line usage error at once, not a failure after the whole run), and the
// commit of each output file turned into the command's failure.
#include <filesystem>
#include <string>

#include "rigcal/core/atomic_file.hpp"

namespace rigcal::app {

/// Creates `folder` (and its parents) and writes and removes a probe file in it. Throws
/// CommandFailed(kExitUsage, "--out <folder>: <reason>").
void prepareOutputFolder(const std::filesystem::path& folder);

/// file.commit(), a failure being CommandFailed(kExitFailure, "<path>: write failed (<reason>)").
void commitOutput(AtomicFile& file);

}  // namespace rigcal::app
