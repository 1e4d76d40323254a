# Tests of jointid_report (included by tests/report/CMakeLists.txt). The tests read the files back
# with VTK's readers, so they link VTK themselves.
find_package(VTK REQUIRED COMPONENTS CommonCore CommonDataModel IOXML IOImage)
add_executable(report_vtk_tests ${CMAKE_CURRENT_LIST_DIR}/vtk_output_test.cpp
                            ${CMAKE_CURRENT_LIST_DIR}/chart_test.cpp)
target_link_libraries(report_vtk_tests PRIVATE jointid_report GTest::gtest_main ${VTK_LIBRARIES})
target_include_directories(report_vtk_tests PRIVATE ${PROJECT_SOURCE_DIR}/tests)
jointid_test_code(report_vtk_tests)
gtest_discover_tests(report_vtk_tests DISCOVERY_TIMEOUT 60)

# A program that writes pictures and ParaView files of a cantilever and a portal frame.
add_executable(report_vtk_demo ${CMAKE_CURRENT_LIST_DIR}/vtk_demo.cpp)
target_link_libraries(report_vtk_demo PRIVATE jointid_report)
target_include_directories(report_vtk_demo PRIVATE ${PROJECT_SOURCE_DIR}/tests)
jointid_test_code(report_vtk_demo)

# Debian's VTK renders through GLX, so pictures need an X server: the discovered VtkPng tests
# skip without DISPLAY, and these run them (and the demo) under a virtual one. xvfb-run -a can
# pick the same display number twice when started in parallel: hence the resource lock.
find_program(XVFB_RUN xvfb-run)
if(XVFB_RUN)
  add_test(NAME report_vtk_png COMMAND ${XVFB_RUN} -a $<TARGET_FILE:report_vtk_tests>
                                   --gtest_filter=VtkPng.*)
  add_test(NAME report_vtk_demo COMMAND ${XVFB_RUN} -a $<TARGET_FILE:report_vtk_demo>
                                    ${CMAKE_CURRENT_BINARY_DIR}/vtk_demo)
  set_tests_properties(report_vtk_png report_vtk_demo PROPERTIES RESOURCE_LOCK xvfb TIMEOUT 120)
else()
  message(STATUS "xvfb-run not found: the mode-picture tests run only with a DISPLAY")
endif()
