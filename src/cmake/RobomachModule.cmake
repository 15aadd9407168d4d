# robomach_add_module(NAME <module> SOURCES ... DEPENDS ...)
# One library per module (style.md §2.1): robomach_<module>, alias
# robomach::<module>, exported as robomach::<module>. DEPENDS lists what the
# module may use; the include check in tests/ enforces the same table.
function(robomach_add_module)
  cmake_parse_arguments(ARG "" "NAME" "SOURCES;DEPENDS;PRIVATE_DEPENDS" ${ARGN})
  set(target robomach_${ARG_NAME})
  add_library(${target} ${ARG_SOURCES})
  add_library(robomach::${ARG_NAME} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${ARG_NAME})
  target_compile_features(${target} PUBLIC cxx_std_20)
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>
    PRIVATE ${PROJECT_SOURCE_DIR}/src)
  target_link_libraries(${target} PUBLIC ${ARG_DEPENDS} PRIVATE ${ARG_PRIVATE_DEPENDS})
  target_compile_options(${target} PRIVATE -Wall -Wextra)
  if(ROBOMACH_EIGEN_NAN_INIT)
    target_compile_definitions(${target} PUBLIC EIGEN_INITIALIZE_MATRICES_BY_NAN)
  endif()
  install(TARGETS ${target} EXPORT robomachTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
endfunction()

# robomach_add_test(NAME <exe> SOURCES ... LIBS ... [LABELS ...] [COST s]): a
# gtest executable registered case by case with ctest. LABELS become ctest
# labels of every case (`ctest -L readers`: the file readers' tests, which CI
# also runs under the sanitizers). COST (seconds, a rough figure) is ctest's
# COST of every case: a parallel run starts the costly ones first, so that a
# fresh checkout (no CTestCostData.txt yet, as in CI) does not end on a
# two-minute test started last on one core.
function(robomach_add_test)
  cmake_parse_arguments(ARG "" "NAME;COST" "SOURCES;LIBS;LABELS" ${ARGN})
  add_executable(${ARG_NAME} ${ARG_SOURCES})
  target_link_libraries(${ARG_NAME} PRIVATE ${ARG_LIBS} GTest::gmock GTest::gtest_main)
  target_include_directories(${ARG_NAME} PRIVATE ${PROJECT_SOURCE_DIR}/tests)
  target_compile_definitions(${ARG_NAME} PRIVATE
    ROBOMACH_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    ROBOMACH_TEST_TMP_DIR="${PROJECT_BINARY_DIR}/test_tmp")
  set(props)
  if(ARG_LABELS)
    list(APPEND props LABELS "${ARG_LABELS}")
  endif()
  if(ARG_COST)
    list(APPEND props COST ${ARG_COST})
  endif()
  if(props)
    gtest_discover_tests(${ARG_NAME} DISCOVERY_TIMEOUT 60 PROPERTIES ${props})
  else()
    gtest_discover_tests(${ARG_NAME} DISCOVERY_TIMEOUT 60)
  endif()
endfunction()
