#pragma once
// CPU time of the calling thread (CLOCK_THREAD_CPUTIME_ID), for rates per CPU-second
// that other load on the machine affects less than rates per wall-clock second.
#include <time.h>

namespace lucent::common {

inline double thread_cpu_seconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

}  // namespace lucent::common
