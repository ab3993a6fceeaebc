# Builds and runs the consumer project (this directory) against ampm as a user would; one
# step per ctest test (c_tests/CMakeLists.txt registers them):
#
#   cmake -DSTEP=<step> -DREPO_ROOT=... -DWORK_DIR=... -DCARGO_TARGET_DIR=...
#         -DNATIVE_STATIC_LIBS=... -DGENERATOR=... -DC_COMPILER=... -DCXX_COMPILER=...
#         [-DPKG_CONFIG=...] -P run.cmake
#
# STEP is one of
#   install        configure the repository root alone, build it and `cmake --install` it
#                  into WORK_DIR/prefix; check that every file arrived
#   find_package   the consumer with find_package(ampm 0.1 CONFIG REQUIRED) on that prefix
#   subdirectory   the consumer with add_subdirectory(<repo>)
#   pkg-config     main.c compiled and linked with a plain compiler command line from
#                  `pkg-config ampm` on that prefix
# Every command is echoed with its output, so a failing test shows what went wrong. The
# nested builds use CARGO_TARGET_DIR and the cached native libraries of the outer build, so
# cargo has nothing to do.
cmake_minimum_required(VERSION 3.16)

foreach(v STEP REPO_ROOT WORK_DIR CARGO_TARGET_DIR NATIVE_STATIC_LIBS GENERATOR C_COMPILER
          CXX_COMPILER)
  if(NOT DEFINED ${v} OR "${${v}}" STREQUAL "")
    message(FATAL_ERROR "run.cmake: pass -D${v}=...")
  endif()
endforeach()
set(SOURCE_DIR "${CMAKE_CURRENT_LIST_DIR}")
set(PREFIX "${WORK_DIR}/prefix")

# run(<command>...): runs it, echoing the command and its output; fails the step on a
# non-zero exit.
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc COMMAND_ECHO STDOUT)
  if(NOT rc EQUAL 0)
    string(REPLACE ";" " " cmd "${ARGN}")
    message(FATAL_ERROR "${STEP}: this command failed (${rc}):\n  ${cmd}")
  endif()
endfunction()

# check_program(<exe> <libampm.so or "none">): the executable's resolved shared libraries
# include exactly that libampm.so (or none at all), and it runs and reports OK.
function(check_program exe expected_so)
  if(NOT EXISTS "${exe}")
    message(FATAL_ERROR "${STEP}: ${exe} was not built")
  endif()
  file(GET_RUNTIME_DEPENDENCIES EXECUTABLES "${exe}"
       RESOLVED_DEPENDENCIES_VAR resolved UNRESOLVED_DEPENDENCIES_VAR unresolved)
  set(found_so "none")
  foreach(lib IN LISTS resolved unresolved)
    if(lib MATCHES "libampm")
      set(found_so "${lib}")
    endif()
  endforeach()
  if(NOT expected_so STREQUAL "none" AND EXISTS "${expected_so}")
    get_filename_component(expected_so "${expected_so}" REALPATH)
  endif()
  if(NOT found_so STREQUAL "none" AND EXISTS "${found_so}")
    get_filename_component(found_so "${found_so}" REALPATH)
  endif()
  if(NOT found_so STREQUAL expected_so)
    message(FATAL_ERROR "${STEP}: ${exe} loads libampm '${found_so}', expected "
                        "'${expected_so}' (resolved: ${resolved}; unresolved: ${unresolved})")
  endif()
  execute_process(COMMAND "${exe}" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  message(STATUS "${exe}: ${out}")
  if(NOT rc EQUAL 0 OR NOT out MATCHES "ampm consumer \\([a-z]+\\): OK")
    message(FATAL_ERROR "${STEP}: ${exe} failed (${rc})")
  endif()
endfunction()

set(common_args -G "${GENERATOR}" -DCMAKE_BUILD_TYPE=Release
    "-DCMAKE_C_COMPILER=${C_COMPILER}" "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}")
set(ampm_args "-DAMPM_CARGO_TARGET_DIR=${CARGO_TARGET_DIR}"
    "-DAMPM_NATIVE_STATIC_LIBS=${NATIVE_STATIC_LIBS}")

# The library directory of the install (lib, or lib64 on some distributions), from the
# root build's cache.
function(read_libdir out)
  file(STRINGS "${WORK_DIR}/root-build/CMakeCache.txt" line REGEX "^CMAKE_INSTALL_LIBDIR:")
  if(NOT line MATCHES "=(.+)$")
    message(FATAL_ERROR "${STEP}: no CMAKE_INSTALL_LIBDIR in ${WORK_DIR}/root-build; "
                        "did consumer_install run?")
  endif()
  set(${out} "${CMAKE_MATCH_1}" PARENT_SCOPE)
endfunction()

if(STEP STREQUAL "install")
  file(REMOVE_RECURSE "${WORK_DIR}/root-build" "${PREFIX}")
  run("${CMAKE_COMMAND}" -S "${REPO_ROOT}" -B "${WORK_DIR}/root-build" ${common_args} ${ampm_args})
  run("${CMAKE_COMMAND}" --build "${WORK_DIR}/root-build")
  run("${CMAKE_COMMAND}" --install "${WORK_DIR}/root-build" --prefix "${PREFIX}")
  read_libdir(libdir)

  # The libraries are the ones cargo built, byte for byte.
  foreach(lib libampm.a libampm.so)
    set(installed "${PREFIX}/${libdir}/${lib}")
    if(NOT EXISTS "${installed}")
      message(FATAL_ERROR "install: ${installed} is missing")
    endif()
    file(SHA256 "${installed}" h_installed)
    file(SHA256 "${CARGO_TARGET_DIR}/release/${lib}" h_built)
    if(NOT h_installed STREQUAL h_built)
      message(FATAL_ERROR "install: ${installed} differs from ${CARGO_TARGET_DIR}/release/${lib}")
    endif()
  endforeach()
  # Every header of include/ (ampm.h, the C++ wrapper if present), unchanged.
  file(GLOB_RECURSE headers RELATIVE "${REPO_ROOT}/include"
       "${REPO_ROOT}/include/*.h" "${REPO_ROOT}/include/*.hpp")
  if(NOT "ampm.h" IN_LIST headers)
    message(FATAL_ERROR "install: ${REPO_ROOT}/include/ampm.h not found")
  endif()
  foreach(h IN LISTS headers)
    if(NOT EXISTS "${PREFIX}/include/${h}")
      message(FATAL_ERROR "install: header ${PREFIX}/include/${h} is missing")
    endif()
    file(SHA256 "${PREFIX}/include/${h}" h_installed)
    file(SHA256 "${REPO_ROOT}/include/${h}" h_source)
    if(NOT h_installed STREQUAL h_source)
      message(FATAL_ERROR "install: ${PREFIX}/include/${h} differs from include/${h}")
    endif()
  endforeach()
  foreach(f cmake/ampm/ampmConfig.cmake cmake/ampm/ampmConfigVersion.cmake pkgconfig/ampm.pc)
    if(NOT EXISTS "${PREFIX}/${libdir}/${f}")
      message(FATAL_ERROR "install: ${PREFIX}/${libdir}/${f} is missing")
    endif()
  endforeach()
  # ampm.pc names the prefix it was installed to, not the configure-time default.
  file(STRINGS "${PREFIX}/${libdir}/pkgconfig/ampm.pc" pc_prefix REGEX "^prefix=")
  if(NOT pc_prefix STREQUAL "prefix=${PREFIX}")
    message(FATAL_ERROR "install: ampm.pc says '${pc_prefix}', expected 'prefix=${PREFIX}'")
  endif()
  message(STATUS "installed ${headers} and the libraries into ${PREFIX}")

elseif(STEP STREQUAL "find_package" OR STEP STREQUAL "subdirectory")
  set(build "${WORK_DIR}/${STEP}")
  file(REMOVE_RECURSE "${build}")
  if(STEP STREQUAL "find_package")
    read_libdir(libdir)
    set(mode_args -DAMPM_CONSUMER_MODE=find_package "-DCMAKE_PREFIX_PATH=${PREFIX}")
    set(shared_lib "${PREFIX}/${libdir}/libampm.so")
  else()
    set(mode_args -DAMPM_CONSUMER_MODE=subdirectory "-DAMPM_SOURCE_DIR=${REPO_ROOT}"
        ${ampm_args})
    set(shared_lib "${CARGO_TARGET_DIR}/release/libampm.so")
  endif()
  run("${CMAKE_COMMAND}" -S "${SOURCE_DIR}" -B "${build}" ${common_args} ${mode_args})
  run("${CMAKE_COMMAND}" --build "${build}")
  check_program("${build}/consumer_static" none)
  check_program("${build}/consumer_shared" "${shared_lib}")

elseif(STEP STREQUAL "pkg-config")
  if(NOT PKG_CONFIG)
    message(FATAL_ERROR
      "pkg-config: no pkg-config program (Debian: apt-get install pkgconf)")
  endif()
  read_libdir(libdir)
  set(ENV{PKG_CONFIG_PATH} "${PREFIX}/${libdir}/pkgconfig")
  foreach(query cflags:--cflags libs:--libs libs_static:--libs,--static)
    string(REGEX REPLACE "[:,]" ";" query "${query}")
    list(POP_FRONT query var)
    list(JOIN query " " query_text)
    execute_process(COMMAND "${PKG_CONFIG}" ${query} ampm RESULT_VARIABLE rc
                    OUTPUT_VARIABLE out ERROR_VARIABLE err OUTPUT_STRIP_TRAILING_WHITESPACE)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "pkg-config ${query_text} ampm failed (${rc}): ${err}")
    endif()
    message(STATUS "pkg-config ${query_text} ampm: ${out}")
    separate_arguments(${var} UNIX_COMMAND "${out}")
  endforeach()
  separate_arguments(native UNIX_COMMAND "${NATIVE_STATIC_LIBS}")
  foreach(lib IN LISTS native)
    if(NOT lib IN_LIST libs_static)
      message(FATAL_ERROR "pkg-config --libs --static ampm lacks ${lib}: ${libs_static}")
    endif()
  endforeach()

  set(out_dir "${WORK_DIR}/pkg-config")
  file(REMOVE_RECURSE "${out_dir}")
  file(MAKE_DIRECTORY "${out_dir}")
  set(cc "${C_COMPILER}" -std=c99 -Wall -Wextra -Wpedantic -Werror)
  # Static: with libampm.a and libampm.so side by side, -lampm alone picks the shared one;
  # -Wl,-Bstatic around it takes the archive, and Libs.private adds its native libraries.
  list(TRANSFORM libs_static REPLACE "^-lampm$" "-Wl,-Bstatic;-lampm;-Wl,-Bdynamic")
  run(${cc} "-DAMPM_CONSUMER_LINK=\"static\"" "${SOURCE_DIR}/main.c" ${cflags}
      ${libs_static} -lm -o "${out_dir}/consumer_static")
  check_program("${out_dir}/consumer_static" none)
  # Shared: `pkg-config --libs ampm`, with an rpath to the prefix.
  run(${cc} "-DAMPM_CONSUMER_LINK=\"shared\"" "${SOURCE_DIR}/main.c" ${cflags} ${libs} -lm
      "-Wl,-rpath,${PREFIX}/${libdir}" -o "${out_dir}/consumer_shared")
  check_program("${out_dir}/consumer_shared" "${PREFIX}/${libdir}/libampm.so")

else()
  message(FATAL_ERROR "run.cmake: unknown STEP '${STEP}'")
endif()
