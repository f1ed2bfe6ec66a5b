# Writes the scenario schema into a C++ source, so the binary carries its single source of truth.
file(READ ${INPUT} text)
file(WRITE ${OUTPUT} "// Generated from schemas/scenario.schema.json; do not edit.\n#include \"pipeline/scenario.hpp\"\nnamespace terrapolis::pipeline {\nstd::string_view scenario_schema_text() {\n  static constexpr char text[] = R\"schema(${text})schema\";\n  return text;\n}\n}  // namespace terrapolis::pipeline\n")
