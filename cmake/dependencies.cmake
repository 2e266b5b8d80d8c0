# The C++ libraries of the front end and the Python package, looked for up front so that every missing
# one is named at once, with the package that provides it, before any target is defined. The
# subdirectories' own find_package calls then find what was found here.
set(_kage_missing "")
# _kage_require(<found?> <what> <Debian package> <conda-forge package>)
macro(_kage_require found what debian conda)
  if(NOT ${found})
    list(APPEND _kage_missing "  ${what}: Debian/Ubuntu `${debian}`, conda-forge `${conda}`")
  endif()
endmacro()

find_package(yaml-cpp QUIET)
_kage_require(yaml-cpp_FOUND "yaml-cpp" libyaml-cpp-dev yaml-cpp)
find_package(fmt QUIET)
_kage_require(fmt_FOUND "fmt" libfmt-dev fmt)
find_package(nlohmann_json QUIET)
_kage_require(nlohmann_json_FOUND "nlohmann-json" nlohmann-json3-dev nlohmann_json)
find_package(CLI11 QUIET)
_kage_require(CLI11_FOUND "CLI11" libcli11-dev cli11)
find_library(KAGE_STB_LIBRARY NAMES stb)
find_path(KAGE_STB_INCLUDE_DIR stb/stb_image.h)
_kage_require(KAGE_STB_LIBRARY "stb (libstb)" libstb-dev "(none: use Debian's libstb-dev, or build stb as libstb)")
if(KAGE_BUILD_PYTHON)
  find_path(KAGE_DLPACK_INCLUDE_DIR dlpack/dlpack.h)
  _kage_require(KAGE_DLPACK_INCLUDE_DIR "dlpack (the Python package; -DKAGE_BUILD_PYTHON=OFF builds without it)"
                libdlpack-dev dlpack)
endif()
if(KAGE_BUILD_TESTS)
  find_package(Catch2 QUIET)
  _kage_require(Catch2_FOUND "Catch2 2.x (the tests; -DKAGE_BUILD_TESTS=OFF builds without them)" catch2 "catch2 2.x")
endif()

if(_kage_missing)
  list(JOIN _kage_missing "\n" _kage_missing_text)
  message(FATAL_ERROR "kage: C++ libraries not found:\n${_kage_missing_text}\n"
                      "Install them (Debian: `apt-get install ...`; without root: `conda install -c conda-forge ...` "
                      "and configure with -DCMAKE_PREFIX_PATH=$CONDA_PREFIX, or for pip "
                      "`CMAKE_PREFIX_PATH=$CONDA_PREFIX pip install .`). README.md, \"Install\", says more.")
endif()
