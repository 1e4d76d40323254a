# Tests of jointid_io_vtk (included by tests/io/CMakeLists.txt). The tests read the files back
# with VTK's readers, so they link VTK themselves.
find_package(VTK REQUIRED COMPONENTS CommonCore CommonDataModel IOXML IOImage)
add_executable(io_vtk_tests ${CMAKE_CURRENT_LIST_DIR}/vtk_output_test.cpp
                            ${CMAKE_CURRENT_LIST_DIR}/chart_test.cpp)
target_link_libraries(io_vtk_tests PRIVATE jointid_io_vtk GTest::gtest_main ${VTK_LIBRARIES})
target_include_directories(io_vtk_tests PRIVATE ${PROJECT_SOURCE_DIR}/tests)
gtest_discover_tests(io_vtk_tests DISCOVERY_TIMEOUT 60)

# A program that writes pictures and ParaView files of a cantilever and a portal frame.
add_executable(io_vtk_demo ${CMAKE_CURRENT_LIST_DIR}/vtk_demo.cpp)
target_link_libraries(io_vtk_demo PRIVATE jointid_io_vtk)
target_include_directories(io_vtk_demo PRIVATE ${PROJECT_SOURCE_DIR}/tests)

# Debian's VTK renders through GLX, so pictures need an X server: the discovered VtkPng tests
# skip without DISPLAY, and these run them (and the demo) under a virtual one. xvfb-run -a can
# pick the same display number twice when started in parallel: hence the resource lock.
find_program(XVFB_RUN xvfb-run)
if(XVFB_RUN)
  add_test(NAME io_vtk_png COMMAND ${XVFB_RUN} -a $<TARGET_FILE:io_vtk_tests>
                                   --gtest_filter=VtkPng.*)
  add_test(NAME io_vtk_demo COMMAND ${XVFB_RUN} -a $<TARGET_FILE:io_vtk_demo>
                                    ${CMAKE_CURRENT_BINARY_DIR}/vtk_demo)
  set_tests_properties(io_vtk_png io_vtk_demo PROPERTIES RESOURCE_LOCK xvfb TIMEOUT 120)
else()
  message(STATUS "xvfb-run not found: the mode-picture tests run only with a DISPLAY")
endif()
