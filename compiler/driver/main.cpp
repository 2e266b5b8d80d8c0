// kagec: argv -> run_kagec; nothing else.
#include <unistd.h>

#include <iostream>

#include "compiler/commands.h"

int main(int argc, char** argv) {
  kage::CommandIo io{std::cout, std::cerr, isatty(STDERR_FILENO) != 0};
  return kage::run_kagec(std::vector<std::string>(argv + 1, argv + argc), io);
}
