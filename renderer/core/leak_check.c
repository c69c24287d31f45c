/* leak_check.c — sl_leak_check.h: the leak check, run from an atexit handler
 * registered after a library that ends threads at exit was started. */
#include <pthread.h>
#include <stdlib.h>

#include "sl_leak_check.h"

#if defined(__SANITIZE_ADDRESS__)
#define SL_HAVE_LSAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(leak_sanitizer)
#define SL_HAVE_LSAN 1
#endif
#endif

#ifdef SL_HAVE_LSAN
#include <sanitizer/lsan_interface.h>

static void leak_check_now(void)
{
    __lsan_do_leak_check();
}

static void register_handler(void)
{
    atexit(leak_check_now);
}
#endif

void sl_leak_check_early(void)
{
#ifdef SL_HAVE_LSAN
    static pthread_once_t once = PTHREAD_ONCE_INIT;
    pthread_once(&once, register_handler);
#endif
}
