# ictk_add_core_library: the one way a library of the VTK-free core (Modules/Core/<Name>) is made.
#
#   ictk_add_core_library(<Name>
#     SOURCES <file>...
#     PRIVATE_HEADERS <file>...               # headers of its sources only: not installed
#     DEPENDS <ICTK core library>...          # public: its headers include theirs
#     PRIVATE_DEPENDS <ICTK core library>...  # used by its sources only
#     LINK <target>... PRIVATE_LINK <target>...   # external libraries (TBB::tbb, Eigen3::Eigen...)
#     [NO_EXPORT])                            # not installed (GPL backends, linked privately)
#
# makes the static library ictk<Name>, its alias ICTK::<Name> (also its installed name), includes
# "<Name>/Header.h" from Modules/Core (build) or include/ictk (install), links ICTK::BuildFlags
# privately, and records the ICTK dependencies in the global property ICTK_CORE_GRAPH, from which
# build/ictk-core-graph.txt is written (ictk_write_core_graph) and checked against
# docs/architecture.md by the test Docs.ArchitectureGraph.
#
# Its public headers are the .h files of its folder that PRIVATE_HEADERS does not name; they are
# installed under include/ictk/<folder below Modules/Core>/, the library into the export set ICTK
# (ICTKConfig.cmake). A header named in PRIVATE_HEADERS that a public header includes would break
# an installed tree: Install.Example builds against one.
function(ictk_add_core_library name)
  cmake_parse_arguments(PARSE_ARGV 1 arg "NO_EXPORT" ""
    "SOURCES;PRIVATE_HEADERS;DEPENDS;PRIVATE_DEPENDS;LINK;PRIVATE_LINK")
  if(arg_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "ictk_add_core_library(${name}): unknown arguments ${arg_UNPARSED_ARGUMENTS}")
  endif()
  set(target ictk${name})
  add_library(${target} ${arg_SOURCES})
  add_library(ICTK::${name} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name})
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/Modules/Core>
    $<INSTALL_INTERFACE:include/ictk>)
  list(TRANSFORM arg_DEPENDS PREPEND "ICTK::" OUTPUT_VARIABLE public_targets)
  list(TRANSFORM arg_PRIVATE_DEPENDS PREPEND "ICTK::" OUTPUT_VARIABLE private_targets)
  target_link_libraries(${target}
    PUBLIC ${public_targets} ${arg_LINK}
    PRIVATE ${private_targets} ${arg_PRIVATE_LINK} ICTK::BuildFlags)
  set(edges "${name}:")
  foreach(dependency IN LISTS arg_DEPENDS)
    string(APPEND edges " ${dependency}")
  endforeach()
  foreach(dependency IN LISTS arg_PRIVATE_DEPENDS)
    string(APPEND edges " ${dependency}(private)")
  endforeach()
  set_property(GLOBAL APPEND PROPERTY ICTK_CORE_GRAPH "${edges}")
  set_property(GLOBAL APPEND PROPERTY ICTK_CORE_LIBRARIES ${target})

  file(GLOB headers RELATIVE ${CMAKE_CURRENT_SOURCE_DIR} CONFIGURE_DEPENDS
    ${CMAKE_CURRENT_SOURCE_DIR}/*.h)
  foreach(header IN LISTS arg_PRIVATE_HEADERS)
    if(NOT header IN_LIST headers)
      message(FATAL_ERROR "ictk_add_core_library(${name}): PRIVATE_HEADERS names ${header}, which is not in ${CMAKE_CURRENT_SOURCE_DIR}")
    endif()
  endforeach()
  if(arg_PRIVATE_HEADERS)
    list(REMOVE_ITEM headers ${arg_PRIVATE_HEADERS})
  endif()
  if(arg_NO_EXPORT OR NOT ICTK_ENABLE_VTK)
    # Nothing to install: the export set and ICTKConfig.cmake come with the VTK layer.
    return()
  endif()
  file(RELATIVE_PATH folder ${PROJECT_SOURCE_DIR}/Modules/Core ${CMAKE_CURRENT_SOURCE_DIR})
  install(FILES ${headers} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/ictk/${folder})
  install(TARGETS ${target} EXPORT ICTK
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endfunction()

# Writes the recorded graph, one line per library ("Name: Dep Dep(private)"), sorted.
function(ictk_write_core_graph file)
  get_property(graph GLOBAL PROPERTY ICTK_CORE_GRAPH)
  list(SORT graph)
  list(JOIN graph "\n" text)
  file(WRITE ${file} "${text}\n")
endfunction()
