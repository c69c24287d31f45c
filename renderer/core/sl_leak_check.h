/* sl_leak_check.h — runs the sanitizer's end-of-process leak check before the
 * libraries tear down their worker threads.
 *
 * Why: LeakSanitizer's end-of-process check stops every thread and reads its
 * stack. A thread that exits while it does so crashes its tracer
 * ("LeakSanitizer has encountered a fatal error", seen once in CI on a
 * sightline-render run that drew tubes with Embree). oneTBB, under Embree,
 * ends its workers from its own exit-time destructors, which run before the
 * sanitizer's check. sl_leak_check_early() registers (once) an atexit handler
 * that runs the same check at that earlier point, while those workers are
 * still parked; the later end-of-process check then does nothing. Leaks are
 * still found and still end the process with the sanitizer's exit code.
 *
 * Limits: a no-op in builds without AddressSanitizer/LeakSanitizer. What
 * atexit handlers registered before the first call free is not yet freed
 * when the check runs; it stays reachable from globals, so it is not a leak.
 * Thread: any; the registration happens once (pthread_once).
 */
#ifndef SL_LEAK_CHECK_H
#define SL_LEAK_CHECK_H

void sl_leak_check_early(void);

#endif
