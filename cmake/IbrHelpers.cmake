# Small helpers shared by the per-folder CMakeLists.

# ibr_library(NAME SOURCES ... [PUBLIC_DEPS ...] [PRIVATE_DEPS ...])
# One static library per top-level folder; include paths are rooted at the
# repository so that headers read "render/context.h".
function(ibr_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${name} PUBLIC ${ARG_PUBLIC_DEPS} ibr_sanitizers
                        PRIVATE ${ARG_PRIVATE_DEPS} ibr_warnings)
endfunction()

# ibr_test(MODULE NAME SOURCES ... [DEPS ...] [LABELS ...] [GL] [TIMEOUT s])
# Registers a GoogleTest executable as ctest test "MODULE/NAME".
# GL tests run with the display removed, so they use the headless EGL path.
function(ibr_test module name)
  cmake_parse_arguments(ARG "GL" "TIMEOUT" "SOURCES;DEPS;LABELS" ${ARGN})
  set(target test_${module}_${name})
  add_executable(${target} ${ARG_SOURCES})
  target_link_libraries(${target} PRIVATE ${ARG_DEPS} ibr_test_main ibr_warnings)
  set_target_properties(${target} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  add_test(NAME ${module}/${name} COMMAND ${target})
  set(env_mod
    "DISPLAY=unset:"
    "WAYLAND_DISPLAY=unset:"
    "MESA_SHADER_CACHE_DISABLE=set:true"
    "IBR_CACHE_DIR=set:off"
    "IBR_SHARED_DATA=set:${IBR_SHARED_DATA_DIR}"
    "IBR_TEST_OUTPUT=set:${CMAKE_BINARY_DIR}/test-output"
    "IBR_SOURCE_DIR=set:${PROJECT_SOURCE_DIR}"
    "ASAN_OPTIONS=set:detect_leaks=0")
  set_tests_properties(${module}/${name} PROPERTIES
    ENVIRONMENT_MODIFICATION "${env_mod}"
    LABELS "${module};${ARG_LABELS}")
  if(ARG_GL)
    set_property(TEST ${module}/${name} APPEND PROPERTY LABELS gl)
  endif()
  if(ARG_TIMEOUT)
    # ASan + UBSan (IBR_SANITIZE) check every memory access, llvmpipe's
    # rasteriser included, so the same work takes several times as long.
    if(IBR_SANITIZE)
      math(EXPR ARG_TIMEOUT "${ARG_TIMEOUT} * 5")
    endif()
    set_tests_properties(${module}/${name} PROPERTIES TIMEOUT ${ARG_TIMEOUT})
  endif()
endfunction()
