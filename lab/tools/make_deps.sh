#!/usr/bin/env bash
# Fills .deps (ignored by git) with what a build on the device machine needs and that machine lacks:
# the Debian packages of yaml-cpp, fmt, stb, nlohmann-json, CLI11 and dlpack, unpacked, Python 3.12's
# headers (from pyenv, if present), and in .deps/wheels the build backend that `pip install .` needs
# there without an index (scikit-build-core, pure Python). Carry it: run's carry [".deps"].
set -euo pipefail
cd "$(dirname "$0")/../.."
rm -rf .deps && mkdir -p .deps/debs
(cd .deps/debs && apt-get download libyaml-cpp-dev libyaml-cpp0.7 libfmt-dev libfmt9 libstb-dev libstb0 \
  nlohmann-json3-dev libcli11-dev libdlpack-dev)
for f in .deps/debs/*.deb; do dpkg -x "$f" .deps; done
rm -rf .deps/debs .deps/usr/share/doc  # the packages' documentation: a call's carry counts against its 64 MiB
if [ -d /root/.pyenv/versions/3.12.1/include/python3.12 ]; then
  mkdir -p .deps/python3.12/include && cp -r /root/.pyenv/versions/3.12.1/include/python3.12 .deps/python3.12/include/
fi
python3 -m pip download -q --no-deps -d .deps/wheels scikit-build-core==1.1.2 pathspec==1.1.1 packaging==26.4
du -sh .deps
