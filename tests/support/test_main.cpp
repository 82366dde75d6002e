// The doctest main of crep_tests and crep_gl_tests (linked from crep_test_support).
#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

int main(int argc, char** argv) {
  doctest::Context context;
  context.applyCommandLine(argc, argv);
  const int result = context.run();
  if (context.shouldExit()) return result; // --help, --list-test-cases, ... (doctest_discover_tests)
  return result;
}
