# lcm-gen wrapper: Debian's LCM 1.3.1 ships no CMake config, so generate the message code here.
#
# panmap_lcm_types(TARGET <name> PACKAGE <pkg> FILES <*.lcm>... [JAVA_JAR <var>])
#   Creates INTERFACE library <name> whose include directory holds <pkg>/<type>.hpp for every
#   struct, links LCM through pkg-config, and (with JAVA_JAR) builds a jar of the Java classes
#   for lcm-spy, storing its path in <var>.
find_program(LCM_GEN_EXECUTABLE lcm-gen REQUIRED)
find_package(PkgConfig REQUIRED)
pkg_check_modules(LCM REQUIRED IMPORTED_TARGET lcm)
set(PANMAP_LCM_CMAKE_DIR ${CMAKE_CURRENT_LIST_DIR})

function(panmap_lcm_types)
  cmake_parse_arguments(ARG "" "TARGET;PACKAGE;JAVA_JAR" "FILES" ${ARGN})
  set(out_dir ${CMAKE_BINARY_DIR}/lcmtypes)
  set(cpp_dir ${out_dir}/include)
  set(headers)
  set(java_sources)
  foreach(lcm_file ${ARG_FILES})
    # One struct per file, named <package>_<struct>.lcm.
    get_filename_component(base ${lcm_file} NAME_WE)
    string(REGEX REPLACE "^${ARG_PACKAGE}_" "" struct_name ${base})
    list(APPEND headers ${cpp_dir}/${ARG_PACKAGE}/${struct_name}.hpp)
    list(APPEND java_sources ${out_dir}/java/${ARG_PACKAGE}/${struct_name}.java)
  endforeach()

  add_custom_command(
    OUTPUT ${headers}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${cpp_dir}
    COMMAND ${LCM_GEN_EXECUTABLE} --cpp --cpp-hpath ${cpp_dir} ${ARG_FILES}
    # Bound array lengths by the message size before the decoders allocate them.
    COMMAND ${CMAKE_COMMAND} -DDIR=${cpp_dir}/${ARG_PACKAGE}
            -P ${PANMAP_LCM_CMAKE_DIR}/PanmapLcmBoundArrays.cmake
    DEPENDS ${ARG_FILES} ${PANMAP_LCM_CMAKE_DIR}/PanmapLcmBoundArrays.cmake
    COMMENT "lcm-gen: C++ headers for ${ARG_PACKAGE}"
    VERBATIM)
  add_custom_target(${ARG_TARGET}_gen DEPENDS ${headers})
  add_library(${ARG_TARGET} INTERFACE)
  add_dependencies(${ARG_TARGET} ${ARG_TARGET}_gen)
  target_include_directories(${ARG_TARGET} SYSTEM INTERFACE $<BUILD_INTERFACE:${cpp_dir}>)
  target_link_libraries(${ARG_TARGET} INTERFACE PkgConfig::LCM)

  if(ARG_JAVA_JAR)
    find_package(Java COMPONENTS Development)
    find_file(LCM_JAR lcm.jar PATHS /usr/share/java /usr/local/share/java)
    if(Java_FOUND AND LCM_JAR)
      include(UseJava)
      set(jar_path ${out_dir}/${ARG_PACKAGE}_lcmtypes.jar)
      set(class_dir ${out_dir}/java_classes)
      add_custom_command(
        OUTPUT ${jar_path}
        COMMAND ${CMAKE_COMMAND} -E remove_directory ${out_dir}/java ${class_dir}
        COMMAND ${CMAKE_COMMAND} -E make_directory ${out_dir}/java ${class_dir}
        COMMAND ${LCM_GEN_EXECUTABLE} --java --jpath ${out_dir}/java ${ARG_FILES}
        COMMAND ${Java_JAVAC_EXECUTABLE} -nowarn -cp ${LCM_JAR} -d ${class_dir} ${java_sources}
        COMMAND ${Java_JAR_EXECUTABLE} cf ${jar_path} -C ${class_dir} .
        DEPENDS ${ARG_FILES}
        COMMENT "lcm-gen: Java jar of ${ARG_PACKAGE} types (for lcm-spy)"
        VERBATIM)
      add_custom_target(${ARG_TARGET}_jar ALL DEPENDS ${jar_path})
      set(${ARG_JAVA_JAR} ${jar_path} PARENT_SCOPE)
    else()
      message(WARNING "No JDK or lcm.jar: the lcm-spy types jar is not built")
    endif()
  endif()
endfunction()
