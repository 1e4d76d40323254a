# Tests of io/, report/ and cli/ (included by tests/CMakeLists.txt).
add_subdirectory(io)
add_subdirectory(report)
add_subdirectory(cli)
