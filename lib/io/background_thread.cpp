#include "io/background_thread.h"

#include <sched.h>
#include <time.h>

#include <cerrno>

namespace rths::io {

bool StartBackgroundThread(pthread_t* thread, void* (*run)(void*), void* arg) {
  constexpr std::size_t kStackBytes = 256 * 1024;
  pthread_attr_t attr;
  ::pthread_attr_init(&attr);
  ::pthread_attr_setstacksize(&attr, kStackBytes);
  ::pthread_attr_setinheritsched(&attr, PTHREAD_EXPLICIT_SCHED);
  ::pthread_attr_setschedpolicy(&attr, SCHED_OTHER);
  sched_param none{};
  ::pthread_attr_setschedparam(&attr, &none);
  const int rc = ::pthread_create(thread, &attr, run, arg);
  ::pthread_attr_destroy(&attr);
  return rc == 0;
}

void SleepMicros(long us) {
  timespec ts{us / 1000000, (us % 1000000) * 1000};
  while (::nanosleep(&ts, &ts) != 0 && errno == EINTR) {
  }
}

}  // namespace rths::io
