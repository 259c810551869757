# storey_module(<target> DIR <folder> [DEPS <libs...>] [EXCLUDE <regex>])
# One library target per top-level folder, built from every .cpp beneath it, so that adding a
# file never means editing CMake. Includes are rooted at the repository ("rt/spsc_queue.hpp").
function(storey_module target)
  cmake_parse_arguments(M "" "DIR;EXCLUDE" "DEPS" ${ARGN})
  file(GLOB_RECURSE srcs CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/${M_DIR}/*.cpp
       ${PROJECT_SOURCE_DIR}/${M_DIR}/*.c)
  if(M_EXCLUDE)
    list(FILTER srcs EXCLUDE REGEX "${M_EXCLUDE}")
  endif()
  if(srcs)
    add_library(${target} STATIC ${srcs})
    target_include_directories(${target} PUBLIC ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR}/generated)
    target_link_libraries(${target} PUBLIC ${M_DEPS})
  else()
    add_library(${target} INTERFACE)
    target_include_directories(${target} INTERFACE ${PROJECT_SOURCE_DIR})
    target_link_libraries(${target} INTERFACE ${M_DEPS})
  endif()
endfunction()

# storey_test_dir(<name> LIBS <libs...> [LABELS <label>])
# Builds every .cpp in the calling folder into one GoogleTest executable test_<name>.
function(storey_test_dir name)
  cmake_parse_arguments(T "" "" "LIBS;LABELS" ${ARGN})
  file(GLOB srcs CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cpp)
  if(NOT srcs)
    return()
  endif()
  foreach(lib ${T_LIBS})
    if(lib MATCHES "^storey_" AND NOT TARGET ${lib})
      message(STATUS "tests/${name}: skipped, ${lib} is not built (STOREY_BUILD_TOOLS=OFF?)")
      return()
    endif()
  endforeach()
  add_executable(test_${name} ${srcs})
  target_link_libraries(test_${name} PRIVATE ${T_LIBS} GTest::gtest GTest::gtest_main GTest::gmock)
  target_compile_definitions(test_${name} PRIVATE STOREY_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
                             STOREY_BINARY_DIR="${PROJECT_BINARY_DIR}")
  # One label per test directory: CMake 3.25's gtest_discover_tests drops all but the first
  # element of a label list. Test names carry the directory ("rt.SpscQueue.Order").
  set(label unit)
  if(T_LABELS)
    list(GET T_LABELS 0 label)
  endif()
  gtest_discover_tests(test_${name} TEST_PREFIX "${name}." PROPERTIES LABELS ${label}
                       DISCOVERY_TIMEOUT 60)
endfunction()
