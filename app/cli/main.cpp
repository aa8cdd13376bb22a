#include "app/cli/cli.h"

// Debian's OpenXR loader 1.0.20 leaks about 1.3 kB per instance (`lobesketch vr`; a do-nothing
// runtime shows the same): not ours to fix, so the leak checker of sanitizer builds ignores
// what it allocates. Only the executable defines this (the test programs have their own).
extern "C" __attribute__((used)) const char* __lsan_default_suppressions()
{
    return "leak:libopenxr_loader.so\n";
}

int main(int argc, char** argv) { return lobe::run_cli(argc, argv); }
