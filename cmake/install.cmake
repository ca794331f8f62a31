# cmake/install.cmake — what `cmake --install build [--prefix DIR]` puts where users look for it:
#   bin/raystream                        the command
#   lib/libraystream.so.*, libraystream.a the C API (include/raystream.h)
#   include/raystream.h
#   lib/pkgconfig/raystream.pc           cc example.c $(pkg-config --cflags --libs raystream)
#   lib/cmake/raystream/                 find_package(raystream) -> raystream::raystream
#   share/man/man1/raystream.1           man raystream (from the command's own --help)
#   share/doc/raystream/                 README.md, docs/api.md, the example program
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

install(TARGETS raystream RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS raystream_shared EXPORT raystreamTargets
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS raystream_static ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(FILES include/raystream.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})

# pkg-config: the shared library; --static adds what libraystream.a needs beside it
set(rs_pc_private "-lstdc++ -lm -lpthread")
if(OpenMP_C_FOUND AND NOT RS_SANITIZE STREQUAL "thread")
  string(PREPEND rs_pc_private "${OpenMP_C_FLAGS} ")
endif()
set(rs_pc_requires "")
foreach(dep OIIO CJSON ASSIMP)
  if(${dep}_FOUND)
    list(APPEND rs_pc_requires_list ${${dep}_MODULE_NAME})
  endif()
endforeach()
if(rs_pc_requires_list)
  string(JOIN ", " rs_pc_requires ${rs_pc_requires_list})
endif()
if(RS_HAVE_CUDA)
  string(APPEND rs_pc_private " -L${CUDAToolkit_LIBRARY_DIR} -lcudart_static -ldl -lrt")
endif()
file(RELATIVE_PATH rs_pc_up "${CMAKE_INSTALL_FULL_LIBDIR}/pkgconfig" "${CMAKE_INSTALL_PREFIX}")
string(REGEX REPLACE "/$" "" rs_pc_up "${rs_pc_up}")
configure_file(${CMAKE_CURRENT_LIST_DIR}/raystream.pc.in ${CMAKE_CURRENT_BINARY_DIR}/raystream.pc
               @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/raystream.pc
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# CMake package: find_package(raystream 0.2) gives raystream::raystream (the shared library)
install(EXPORT raystreamTargets NAMESPACE raystream::
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/raystream)
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/raystreamConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/raystreamConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/raystream)
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/raystreamConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/raystreamConfig.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/raystreamConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/raystream)

# the manual page, made from the command's help when it is built
add_custom_command(OUTPUT ${CMAKE_CURRENT_BINARY_DIR}/raystream.1
  COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/scripts/make-man.sh $<TARGET_FILE:raystream>
          ${PROJECT_VERSION} ${CMAKE_CURRENT_BINARY_DIR}/raystream.1
  DEPENDS raystream ${CMAKE_CURRENT_SOURCE_DIR}/scripts/make-man.sh
  COMMENT "Making the manual page raystream.1")
add_custom_target(raystream_man ALL DEPENDS ${CMAKE_CURRENT_BINARY_DIR}/raystream.1)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/raystream.1 DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
install(FILES README.md docs/api.md examples/render.c
        DESTINATION ${CMAKE_INSTALL_DOCDIR})
