#pragma once
// A reader copies slots out of a mapping whose size another process (of the ring's owner: the mode is
// 0600) can cut at any moment. The fstat check before each read (ScanRingReader::Impl::requireIntact)
// leaves a window: a truncation during the copy makes the next touched page raise SIGBUS, which kills the
// process. This guard turns a SIGBUS raised inside `fn` on the calling thread into a false return; a SIGBUS
// anywhere else gets the disposition that was there before (default: the process dies, as without it).
//
// `fn` must only touch memory and trivially destructible locals (it is left by siglongjmp): the ring's copy
// loops qualify; anything that allocates, locks or owns resources does not.
namespace rigcal::shm::detail {

/// Runs fn(context). False when it was cut short by a SIGBUS (a mapping lost its pages under it).
bool runCatchingSigbus(void (*fn)(void*), void* context);

/// The lambda form: `f` is called once; same rules as above.
template <class F>
bool runCatchingSigbus(F& f) {
  return runCatchingSigbus([](void* c) { (*static_cast<F*>(c))(); }, &f);
}

}  // namespace rigcal::shm::detail
