#include <CLI/CLI.hpp>
int main(int argc, char** argv) {
  CLI::App app{"rigcal"};
  app.set_version_flag("--version", RIGCAL_VERSION);
  CLI11_PARSE(app, argc, argv);
  return 0;
}
