# Compile and link against copies of the dependencies that live at a stable path.
# (The other half of "one build": the objects live in core/, see CMakeLists.txt.)
#
# Why: pip's build isolation installs pybind11, Eigen and coal into a fresh temporary folder
# for every `pip install`, and writes their files with new modification times. Every compile
# line would name a new include folder and every header would look newer than the objects,
# so ninja would rebuild everything although build/{wheel_tag} holds the objects of the last
# build. Instead, each configure copies the headers and libraries into ${CMAKE_BINARY_DIR}/
# deps with copy_if_different, which leaves unchanged files (and their times) alone, and the
# imported targets are pointed at the copies: the commands, and the files they read, are the
# same as last time, and nothing is compiled again.
#
# abdsim_stabilise_dependencies(<prefix>...) maps every path under each <prefix> (the cmeel
# prefix, pybind11's include folder) to deps/<n>/ in the properties of every imported target
# of this directory.

function(_abdsim_copy_file src dst)
  get_filename_component(dst_dir "${dst}" DIRECTORY)
  file(MAKE_DIRECTORY "${dst_dir}")
  execute_process(COMMAND "${CMAKE_COMMAND}" -E copy_if_different "${src}" "${dst}"
                  RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "abdsim: could not copy ${src} to ${dst}")
  endif()
endfunction()

function(abdsim_stabilise_dependencies)
  set(deps_dir "${CMAKE_BINARY_DIR}/deps")
  set(prefixes "")
  set(copies "")
  set(index 0)
  foreach(prefix IN LISTS ARGN)
    if(NOT prefix OR NOT IS_DIRECTORY "${prefix}")
      continue()
    endif()
    # Targets may name the folder as given or through its resolved path: map both.
    file(REAL_PATH "${prefix}" real)
    list(APPEND prefixes "${prefix}")
    list(APPEND copies "${deps_dir}/${index}")
    if(NOT real STREQUAL prefix)
      list(APPEND prefixes "${real}")
      list(APPEND copies "${deps_dir}/${index}")
    endif()
    math(EXPR index "${index} + 1")
  endforeach()
  list(LENGTH prefixes n_prefixes)
  if(n_prefixes EQUAL 0)
    return()
  endif()
  math(EXPR last "${n_prefixes} - 1")

  set(properties INTERFACE_INCLUDE_DIRECTORIES INTERFACE_SYSTEM_INCLUDE_DIRECTORIES
      INTERFACE_LINK_LIBRARIES IMPORTED_LOCATION)
  foreach(config IN ITEMS RELEASE DEBUG RELWITHDEBINFO MINSIZEREL NOCONFIG)
    list(APPEND properties IMPORTED_LOCATION_${config} IMPORTED_IMPLIB_${config})
  endforeach()

  set(include_dirs "")
  set(files "")
  get_property(targets DIRECTORY PROPERTY IMPORTED_TARGETS)
  foreach(target IN LISTS targets)
    foreach(property IN LISTS properties)
      get_target_property(value ${target} ${property})
      if(NOT value)
        continue()
      endif()
      set(new_value "")
      foreach(item IN LISTS value)
        # Generator expressions wrap plain paths: look at the path inside.
        string(REGEX REPLACE "^\\$<BUILD_INTERFACE:(.*)>$" "\\1" path "${item}")
        foreach(i RANGE ${last})
          list(GET prefixes ${i} prefix)
          list(GET copies ${i} copy)
          string(FIND "${path}" "${prefix}/" at)
          if(at EQUAL 0 OR path STREQUAL prefix)
            string(REPLACE "${prefix}" "${copy}" stable "${path}")
            if(property MATCHES "INCLUDE_DIRECTORIES")
              list(APPEND include_dirs "${path}|${stable}")
            else()
              list(APPEND files "${path}|${stable}")
            endif()
            string(REPLACE "${path}" "${stable}" item "${item}")
            break()
          endif()
        endforeach()
        list(APPEND new_value "${item}")
      endforeach()
      set_target_properties(${target} PROPERTIES ${property} "${new_value}")
    endforeach()
  endforeach()

  list(REMOVE_DUPLICATES include_dirs)
  list(REMOVE_DUPLICATES files)
  foreach(pair IN LISTS include_dirs)
    string(REPLACE "|" ";" pair "${pair}")
    list(GET pair 0 src)
    list(GET pair 1 dst)
    message(STATUS "abdsim: headers of ${src} -> ${dst}")
    execute_process(COMMAND "${CMAKE_COMMAND}" -E copy_directory_if_different "${src}" "${dst}"
                    RESULT_VARIABLE rc)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "abdsim: could not copy ${src} to ${dst}")
    endif()
  endforeach()
  foreach(pair IN LISTS files)
    string(REPLACE "|" ";" pair "${pair}")
    list(GET pair 0 src)
    list(GET pair 1 dst)
    if(EXISTS "${src}" AND NOT IS_DIRECTORY "${src}")
      _abdsim_copy_file("${src}" "${dst}")
    endif()
  endforeach()
endfunction()
