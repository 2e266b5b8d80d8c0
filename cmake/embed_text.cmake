# Writes a C++ source defining `const std::string& ${NAME}()` that returns the
# contents of ${INPUT}. Run at build time: cmake -DINPUT=... -DOUTPUT=... -DNAME=... -P embed_text.cmake
file(READ "${INPUT}" content)
set(delim "KAGE_EMBED")
file(WRITE "${OUTPUT}.tmp"
"// Generated from ${INPUT_NAME} at build time; do not edit.
#include <string>
namespace kage {
const std::string& ${NAME}() {
  static const std::string text = R\"${delim}(${content})${delim}\";
  return text;
}
}  // namespace kage
")
file(COPY_FILE "${OUTPUT}.tmp" "${OUTPUT}" ONLY_IF_DIFFERENT)
