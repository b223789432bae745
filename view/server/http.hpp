// What the trace view's server and the live view's server share around cpp-httplib: the same
// settings and bind, and a start and a stop that do not race. Included by view/server's .cpp files
// only (it exposes httplib).
#pragma once

#include <httplib.h>

#include <atomic>
#include <string>

namespace graspsim::view {

// Sets what both servers serve alike (the page's files from `web`, .js as a type httplib does
// not compress, an empty /favicon.ico, 1 s keep-alive, SO_REUSEADDR without SO_REUSEPORT) and
// binds 127.0.0.1:`port` (0: any free port). Returns the port bound; throws ViewError naming the
// port, and what to do, when it cannot be bound.
int configure_and_bind(httplib::Server& http, const std::string& web, int port);

// Runs listen_after_bind() on the calling thread and sets `returned` once it has returned.
bool listen_marking(httplib::Server& http, std::atomic<bool>& returned);

// Waits (1 ms sleeps, at most `limit_s` seconds) until `http` runs or its listen has returned.
// True when it runs.
bool wait_running(const httplib::Server& http, const std::atomic<bool>& returned, double limit_s);

// Stops `http` and returns once its listen has returned. httplib's stop() does nothing before
// the listening thread has marked itself running (cpp-httplib 0.11, issue #1371), so one call
// made just after the thread started can be lost: stop() is repeated, 1 ms apart, until
// listen_marking() has returned. Call it only when listen_marking() runs or will run.
void stop_until_returned(httplib::Server& http, const std::atomic<bool>& returned);

}  // namespace graspsim::view
