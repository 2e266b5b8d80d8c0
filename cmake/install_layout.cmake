# What `cmake --install` and a pip wheel install, in one tree under the prefix:
#   bin/kagec
#   share/kagec/{runtime,configs,suites,assets,schemas}
# so an installed kagec finds the runtime headers beside itself (compiler/codegen/build.cpp
# runtime_include_dir) and the Python package finds the shipped files through its distribution's file
# list (python/kage/resources.py). A wheel's prefix is its data folder (pyproject.toml wheel.install-dir),
# which pip unpacks into the environment's prefix; the Python package itself goes to site-packages
# (python/CMakeLists.txt). runtime/ and driver/ install their headers and kagec.

# The shipped configs, suites, assets and schemas keep their relative layout: configs name assets as
# ../../../assets/..., suites name configs as ../configs/...
install(DIRECTORY ${PROJECT_SOURCE_DIR}/configs ${PROJECT_SOURCE_DIR}/suites ${PROJECT_SOURCE_DIR}/assets
                  ${PROJECT_SOURCE_DIR}/schemas
        DESTINATION share/kagec)
