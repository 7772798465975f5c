#include "output_folder.hpp"

#include <system_error>

#include "commands.hpp"
#include "exit_codes.hpp"

namespace rigcal::app {

void prepareOutputFolder(const std::filesystem::path& folder) {
  const std::string what = "--out " + folder.string() + ": ";
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) throw CommandFailed(kExitUsage, what + "cannot create the folder (" + ec.message() + ")");
  if (!std::filesystem::is_directory(folder, ec)) throw CommandFailed(kExitUsage, what + "not a folder");
  try {
    AtomicFile probe(folder / "rigcal-write-probe");  // removed again by its destructor (never committed)
    probe.stream() << "probe";
    probe.stream().flush();
    if (!probe.stream()) throw std::runtime_error("cannot write into it");
  } catch (const std::runtime_error& e) {
    throw CommandFailed(kExitUsage, what + "not writable: " + e.what());
  }
}

void commitOutput(AtomicFile& file) {
  try {
    file.commit();
  } catch (const std::runtime_error& e) {
    throw CommandFailed(kExitFailure, e.what());
  }
}

}  // namespace rigcal::app
