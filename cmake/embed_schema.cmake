# Writes a JSON Schema into a C++ source, so the binary carries its single source of truth.
# -DINPUT=schema.json -DOUTPUT=file.cpp [-DNAMESPACE=ns -DFUNCTION=name -DINCLUDE=header]
# (by default the scenario schema: pipeline::scenario_schema_text() of pipeline/scenario.hpp).
if(NOT NAMESPACE)
  set(NAMESPACE terrapolis::pipeline)
  set(FUNCTION scenario_schema_text)
  set(INCLUDE pipeline/scenario.hpp)
endif()
get_filename_component(name ${INPUT} NAME)
file(READ ${INPUT} text)
file(WRITE ${OUTPUT} "// Generated from schemas/${name}; do not edit.\n#include \"${INCLUDE}\"\nnamespace ${NAMESPACE} {\nstd::string_view ${FUNCTION}() {\n  static constexpr char text[] = R\"schema(${text})schema\";\n  return text;\n}\n}  // namespace ${NAMESPACE}\n")
