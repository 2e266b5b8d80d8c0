// kagec: argv -> run_kagec; nothing else but the last word on standard output and out of memory.
#include <unistd.h>

#include <iostream>
#include <new>

#include "driver/commands.h"

int main(int argc, char** argv) {
  kage::CommandIo io{std::cout, std::cerr, isatty(STDERR_FILENO) != 0};
  try {
    const int code = kage::run_kagec(std::vector<std::string>(argv + 1, argv + argc), io);
    // Standard output is a file too (`kagec resolve F > out.json`): a write that failed is an error.
    if (!(std::cout << std::flush)) {
      std::cerr << "kagec: error: cannot write the standard output\n";
      return code == 0 ? 1 : code;
    }
    return code;
  } catch (const std::bad_alloc&) {
    // Commands refuse sizes they can foresee; this is what remains (e.g. memory taken by others).
    std::cerr << "kagec: error: out of memory; use fewer environments, steps or frames\n";
    return 1;
  }
}
