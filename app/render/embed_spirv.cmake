# Writes OUT: the SPIR-V files in FILES ("|"-separated) as 32-bit word tables, looked up by
# the shader's file name (app/render/embedded_shaders.h), so the program needs no files beside it.
string(REPLACE "|" ";" FILES "${FILES}")
set(body "// Generated from app/render/shaders by embed_spirv.cmake: do not edit.\n#include \"app/render/embedded_shaders.h\"\n\n#include <array>\n\nnamespace lobe {\nnamespace {\n")
set(table "")
set(i 0)
foreach(f ${FILES})
  get_filename_component(name ${f} NAME_WLE)
  file(READ ${f} hex HEX)
  # SPIR-V is a stream of little-endian 32-bit words: bytes b0 b1 b2 b3 make 0xb3b2b1b0.
  string(REGEX REPLACE "([0-9a-f][0-9a-f])([0-9a-f][0-9a-f])([0-9a-f][0-9a-f])([0-9a-f][0-9a-f])" "0x\\4\\3\\2\\1u," words "${hex}")
  string(APPEND body "const std::uint32_t kSpirv${i}[] = {${words}};\n")
  string(APPEND table "    {\"${name}\", std::span<const std::uint32_t>(kSpirv${i})},\n")
  math(EXPR i "${i} + 1")
endforeach()
string(APPEND body "} // namespace\n\nstd::span<const std::uint32_t> embedded_shader(std::string_view name)\n{\n    static const std::array<std::pair<std::string_view, std::span<const std::uint32_t>>, ${i}> shaders{{\n${table}    }};\n    for (const auto& [n, code] : shaders)\n        if (n == name) return code;\n    return {};\n}\n\n} // namespace lobe\n")
file(WRITE ${OUT}.tmp "${body}")
file(COPY_FILE ${OUT}.tmp ${OUT} ONLY_IF_DIFFERENT)
