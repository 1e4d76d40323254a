# jointid_io_vtk: VTK files of meshes and mode shapes, PNG pictures of modes. The only target
# that links VTK, privately: its header has no VTK includes, and nothing else needs VTK.
find_package(VTK REQUIRED COMPONENTS CommonCore CommonDataModel IOXML IOImage RenderingCore
                                     RenderingOpenGL2 RenderingFreeType)
add_library(jointid_io_vtk ${CMAKE_CURRENT_LIST_DIR}/vtk_output.cpp
                           ${CMAKE_CURRENT_LIST_DIR}/vtk_display.cpp)
target_link_libraries(jointid_io_vtk PUBLIC jointid_fem PRIVATE ${VTK_LIBRARIES})
# Registers the OpenGL render window and the FreeType text renderer with VTK's factories.
vtk_module_autoinit(TARGETS jointid_io_vtk MODULES ${VTK_LIBRARIES})
# Debian's VTK renders through GLX: the display check opens the X display itself.
find_package(X11)
if(X11_FOUND)
  target_link_libraries(jointid_io_vtk PRIVATE X11::X11)
endif()
