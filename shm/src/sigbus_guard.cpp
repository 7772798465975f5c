#include "sigbus_guard.hpp"

#include <csetjmp>
#include <csignal>
#include <mutex>

namespace rigcal::shm::detail {
namespace {

thread_local sigjmp_buf* t_landing = nullptr;  // set while this thread runs a guarded function
struct sigaction g_previous {};
std::once_flag g_installed;

void onSigbus(int /*signal*/, siginfo_t* /*info*/, void* /*context*/) {
  if (t_landing != nullptr) siglongjmp(*t_landing, 1);
  // Not a guarded copy: restore what was there (the default kills the process) and return; the faulting
  // access repeats under it.
  ::sigaction(SIGBUS, &g_previous, nullptr);
}

void install() {
  struct sigaction sa {};
  sa.sa_sigaction = onSigbus;
  sa.sa_flags = SA_SIGINFO;
  sigemptyset(&sa.sa_mask);
  ::sigaction(SIGBUS, &sa, &g_previous);
}

}  // namespace

bool runCatchingSigbus(void (*fn)(void*), void* context) {
  std::call_once(g_installed, install);
  sigjmp_buf landing;
  sigjmp_buf* const outer = t_landing;
  // savemask = 1: the handler runs with SIGBUS blocked; leaving it by siglongjmp must unblock it again.
  if (sigsetjmp(landing, 1) != 0) {
    t_landing = outer;
    return false;
  }
  t_landing = &landing;
  fn(context);
  t_landing = outer;
  return true;
}

}  // namespace rigcal::shm::detail
