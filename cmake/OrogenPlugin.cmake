# orogen_add_plugin(NAME SOURCES file... [LIBRARIES lib...])
#
# Builds an orogen plugin: a shared library loaded at run time with Boost.DLL.
# In the orogen tree it lands in <build>/lib/orogen/plugins, beside the
# others; in a separate project (find_package(orogen)) it lands in that
# project's build folder, and OROGEN_PLUGIN_PATH points orogen at it.
function(orogen_add_plugin name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBRARIES" ${ARGN})
  add_library(${name} MODULE ${ARG_SOURCES})
  if(TARGET orogen::kernel)
    target_link_libraries(${name} PRIVATE orogen::kernel ${ARG_LIBRARIES})
  else()
    target_link_libraries(${name} PRIVATE orogen_kernel ${ARG_LIBRARIES})
  endif()
  set_target_properties(${name} PROPERTIES
    PREFIX "" CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON
    CXX_STANDARD 20 CXX_STANDARD_REQUIRED ON)
  # In orogen's own tree, the layering check (cmake/OrogenLayering.cmake) walks this plugin's links.
  set_property(GLOBAL APPEND PROPERTY OROGEN_PLUGIN_TARGETS ${name})
  if(DEFINED OROGEN_PLUGIN_OUTPUT_DIR)
    set_target_properties(${name} PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${OROGEN_PLUGIN_OUTPUT_DIR})
    install(TARGETS ${name} LIBRARY DESTINATION ${OROGEN_PLUGIN_SUBDIR})
  endif()
endfunction()
