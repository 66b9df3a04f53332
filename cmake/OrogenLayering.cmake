# The layering rule, checked at the end of configuration (issue 30):
#
#   kernel <- gl <- libs <- plugins, viewer
#
# A plugin (plugins/<kind>/<name>/) links the kernel, gl, libs/* and its own folder's libraries, never a
# library defined in another plugin's folder: code two plugins share belongs in libs/. libs/, the viewer,
# gl/ and the kernel never link plugin code at all. Tests and benchmarks may link any core they test.
# orogen_add_plugin() registers every plugin target; orogen_check_layering() walks each registered
# plugin's and each library's link closure and stops configuration with the offending edge.

function(_orogen_owner_folder target out)  # plugins/<kind>/<name>, libs/<name>, viewer, kernel, gl, or ""
  get_target_property(dir ${target} SOURCE_DIR)
  file(RELATIVE_PATH rel ${PROJECT_SOURCE_DIR} ${dir})
  if(rel MATCHES "^(plugins/[^/]+/[^/]+)")
    set(${out} ${CMAKE_MATCH_1} PARENT_SCOPE)
  elseif(rel MATCHES "^(libs/[^/]+|viewer|kernel|gl|shaders)")
    set(${out} ${CMAKE_MATCH_1} PARENT_SCOPE)
  else()
    set(${out} "" PARENT_SCOPE)
  endif()
endfunction()

function(_orogen_link_closure target out)  # every in-tree (non-imported) target `target` links, transitively
  set(seen "")
  set(todo ${target})
  while(todo)
    list(POP_FRONT todo current)
    foreach(property LINK_LIBRARIES INTERFACE_LINK_LIBRARIES)
      get_target_property(links ${current} ${property})
      if(NOT links)
        continue()
      endif()
      foreach(link ${links})
        if(link MATCHES "^\\$<LINK_ONLY:(.+)>$")
          set(link ${CMAKE_MATCH_1})
        endif()
        if(NOT TARGET ${link} OR link IN_LIST seen)
          continue()
        endif()
        get_target_property(imported ${link} IMPORTED)
        get_target_property(aliased ${link} ALIASED_TARGET)
        if(aliased)
          set(link ${aliased})
        elseif(imported)
          continue()
        endif()
        list(APPEND seen ${link})
        list(APPEND todo ${link})
      endforeach()
    endforeach()
  endwhile()
  set(${out} ${seen} PARENT_SCOPE)
endfunction()

function(orogen_check_layering)
  get_property(plugins GLOBAL PROPERTY OROGEN_PLUGIN_TARGETS)
  get_property(lib_dirs DIRECTORY ${PROJECT_SOURCE_DIR}/libs PROPERTY SUBDIRECTORIES)
  set(checked ${plugins})
  foreach(dir ${lib_dirs} ${PROJECT_SOURCE_DIR}/kernel ${PROJECT_SOURCE_DIR}/gl)
    if(NOT EXISTS ${dir}/CMakeLists.txt)
      continue()
    endif()
    get_property(targets DIRECTORY ${dir} PROPERTY BUILDSYSTEM_TARGETS)
    list(APPEND checked ${targets})
  endforeach()
  if(TARGET orogen-view)
    list(APPEND checked orogen-view)
  endif()
  foreach(target ${checked})
    _orogen_owner_folder(${target} owner)
    _orogen_link_closure(${target} linked)
    foreach(link ${linked})
      _orogen_owner_folder(${link} link_owner)
      if(link_owner MATCHES "^plugins/" AND NOT link_owner STREQUAL owner)
        message(FATAL_ERROR "layering: ${target} (${owner}) links ${link}, a library defined in ${link_owner}. "
          "A plugin may link the kernel, gl, libs/* and its own folder's code only, and libs, the viewer and the "
          "kernel never link plugin code: move what both need into a folder of libs/ (see docs/architecture.md).")
      endif()
    endforeach()
  endforeach()
endfunction()

# A library's code lives in orogen::<folder>, or in a namespace inside it when the folder holds several
# things (orogen::formats::raw, orogen::solvers::diffusion): the folder a reader opens is the name they
# see in the code. Checked at configure time over the folder's headers and sources (namespace lines at the
# start of a line), so a new library, or a file moved between two, cannot drift.
function(orogen_check_lib_namespaces dir)  # dir: libs/<folder>
  get_filename_component(folder "${dir}" NAME)
  file(GLOB_RECURSE files "${dir}/include/*.hpp" "${dir}/src/*.[ch]pp")
  foreach(file IN LISTS files)
    file(STRINGS "${file}" lines REGEX "^namespace orogen([ {]|::)")
    foreach(line IN LISTS lines)
      string(REGEX MATCH "^namespace (orogen[A-Za-z0-9_:]*)" _ "${line}")
      if(NOT CMAKE_MATCH_1 MATCHES "^orogen::${folder}(::|$)")
        get_filename_component(root "${dir}/../.." ABSOLUTE)
        file(RELATIVE_PATH rel "${root}" "${file}")
        message(FATAL_ERROR "${rel}: '${line}': the code of libs/${folder} belongs in namespace "
                            "orogen::${folder} (or one inside it, orogen::${folder}::NAME); rename the namespace, "
                            "or move the file to the library its namespace names")
      endif()
    endforeach()
  endforeach()
endfunction()
