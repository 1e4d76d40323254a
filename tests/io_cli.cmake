# Tests of io/ and cli/ (included by tests/CMakeLists.txt).
add_subdirectory(io)
add_subdirectory(cli)
