# jointid_report: VTK files of meshes and mode shapes, PNG pictures of modes, and charts (VTK's
# 2D charts drawn through its OpenGL context device). The only target that links VTK, privately:
# its headers have no VTK includes, and nothing else needs VTK.
# Debian builds VTK with MPI: ChartsCore's private dependencies (InfovisCore → FiltersExtraction
# → ParallelMPI) name the imported target MPI::MPI_C, which CMake must know to generate. FindMPI's
# C component needs the C language, which this project does not enable, and nothing here calls
# MPI: those are private dependencies of VTK's shared libraries (libmpi is found by the loader),
# never on our link lines, so an empty placeholder serves, visible from every directory.
if(NOT TARGET MPI::MPI_C)
  add_library(MPI::MPI_C INTERFACE IMPORTED GLOBAL)
endif()
find_package(VTK REQUIRED COMPONENTS CommonCore CommonDataModel IOXML IOImage RenderingCore
                                     RenderingOpenGL2 RenderingFreeType ChartsCore
                                     RenderingContext2D RenderingContextOpenGL2)
list(TRANSFORM JOINTID_REPORT_SOURCES PREPEND ${CMAKE_CURRENT_LIST_DIR}/ OUTPUT_VARIABLE
     report_sources)
add_library(jointid_report ${report_sources} ${CMAKE_CURRENT_LIST_DIR}/vtk_output.cpp
                           ${CMAKE_CURRENT_LIST_DIR}/vtk_display.cpp
                           ${CMAKE_CURRENT_LIST_DIR}/vtk_render.cpp
                           ${CMAKE_CURRENT_LIST_DIR}/chart.cpp)
target_link_libraries(jointid_report PUBLIC jointid_discover jointid_io
                      PRIVATE ${VTK_LIBRARIES} nlohmann_json::nlohmann_json fmt::fmt)
# Registers the OpenGL render window, the FreeType text renderer and the OpenGL context device
# (which draws the charts) with VTK's factories.
vtk_module_autoinit(TARGETS jointid_report MODULES ${VTK_LIBRARIES})
# Debian's VTK renders through GLX: the display check opens the X display itself.
find_package(X11)
if(X11_FOUND)
  target_link_libraries(jointid_report PRIVATE X11::X11)
endif()
