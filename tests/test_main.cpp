// The one Catch2 main for every test executable. Both of Catch's warnings are errors here, for
// every run (ctest's and by hand): a test name that matches no test case (NoTests: a ctest name
// cut at a ';' would otherwise pass having run nothing) and a test case that checks nothing
// (NoAssertions: a test that returned early would otherwise pass). Catch2 v2 takes only one
// `-w` on its command line, so they are set here, after it is read.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

int main(int argc, char* argv[]) {
  Catch::Session session;
  if (const int bad = session.applyCommandLine(argc, argv); bad != 0) return bad;
  session.configData().warnings = static_cast<Catch::WarnAbout::What>(
      session.configData().warnings | Catch::WarnAbout::NoAssertions | Catch::WarnAbout::NoTests);
  return session.run();
}
