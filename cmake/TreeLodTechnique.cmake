# treelod_add_technique(<Name>
#   [RUNTIME_SOURCES src...] [RUNTIME_LIBS lib...]   the chunk format, its descriptor (TechniqueDescriptor.h)
#   [BAKE_SOURCES src...]    [BAKE_LIBS lib...]      the baker and its registration (BakeTechniques.h)
#   [OGRE_SOURCES src...]    [OGRE_LIBS lib...])     the Ogre technique (TechniqueRegistry.h), built into Plugin_TreeLod
#
# One technique = one folder with an include/ directory and this call; its media/ folder (material
# and program scripts, GLSL/), when it has one, joins TreeLod's resource location (the build tree's
# share/TreeLod/media and the installed one: treelod_merge_media). Each half is a static
# library (TreeLod<Name>Runtime, TreeLod<Name>Bake, TreeLod<Name>Ogre) whose namespace-scope
# registration object registers the technique; it is linked whole (WHOLE_ARCHIVE) into the
# aggregates TreeLodTechniques (runtime halves), TreeLodBakeTechniques (bake halves) and into
# Plugin_TreeLod (Ogre halves), so that registration runs wherever the aggregate is linked.
# Nothing else in the build names a technique. The halves and aggregates are installed and exported
# by cmake/TreeLodInstall.cmake (it reads TREELOD_TECHNIQUE_TARGETS).

# treelod_link_whole(<aggregate> <library>): <aggregate> links <library> whole, in the build tree and
# in the installed package. install(EXPORT) does not put its namespace on a target named inside
# $<LINK_LIBRARY:...>, so the installed form names TreeLod::<library> itself.
function(treelod_link_whole aggregate library)
  target_link_libraries(${aggregate} INTERFACE
    "$<BUILD_INTERFACE:$<LINK_LIBRARY:WHOLE_ARCHIVE,${library}>>"
    "$<INSTALL_INTERFACE:$<LINK_LIBRARY:WHOLE_ARCHIVE,TreeLod::${library}>>")
endfunction()

function(treelod_add_technique name)
  cmake_parse_arguments(T "" "" "RUNTIME_SOURCES;RUNTIME_LIBS;BAKE_SOURCES;BAKE_LIBS;OGRE_SOURCES;OGRE_LIBS" ${ARGN})
  set(include $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include> $<INSTALL_INTERFACE:include>)
  if(IS_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/media)
    set_property(GLOBAL APPEND PROPERTY TREELOD_MEDIA_DIRS ${CMAKE_CURRENT_SOURCE_DIR}/media)
  endif()
  if(T_RUNTIME_SOURCES)
    add_library(TreeLod${name}Runtime STATIC ${T_RUNTIME_SOURCES})
    target_include_directories(TreeLod${name}Runtime PUBLIC ${include})
    target_link_libraries(TreeLod${name}Runtime PUBLIC TreeLodRuntime ${T_RUNTIME_LIBS}
      PRIVATE nlohmann_json::nlohmann_json $<BUILD_INTERFACE:treelod_warnings>)
    treelod_link_whole(TreeLodTechniques TreeLod${name}Runtime)
    set_property(GLOBAL APPEND PROPERTY TREELOD_TECHNIQUE_TARGETS TreeLod${name}Runtime)
  endif()
  if(T_BAKE_SOURCES)
    add_library(TreeLod${name}Bake STATIC ${T_BAKE_SOURCES})
    target_include_directories(TreeLod${name}Bake PUBLIC ${include})
    target_link_libraries(TreeLod${name}Bake PUBLIC TreeLodBake TreeLodTechniques ${T_BAKE_LIBS}
      PRIVATE nlohmann_json::nlohmann_json $<BUILD_INTERFACE:treelod_warnings>)
    treelod_link_whole(TreeLodBakeTechniques TreeLod${name}Bake)
    set_property(GLOBAL APPEND PROPERTY TREELOD_TECHNIQUE_TARGETS TreeLod${name}Bake)
  endif()
  if(T_OGRE_SOURCES AND TARGET Plugin_TreeLod)
    add_library(TreeLod${name}Ogre STATIC ${T_OGRE_SOURCES})
    target_include_directories(TreeLod${name}Ogre PUBLIC ${include})
    # The plugin's headers and every technique's (TreeLodTechniques): an Ogre half may use another's
    # classes, as the octahedral impostor draws with the impostor's ImpostorTree; all are in the plugin.
    target_link_libraries(TreeLod${name}Ogre PUBLIC TreeLodOgreHeaders ${T_OGRE_LIBS} PRIVATE treelod_warnings)
    target_link_libraries(Plugin_TreeLod PRIVATE "$<LINK_LIBRARY:WHOLE_ARCHIVE,TreeLod${name}Ogre>")
  endif()
endfunction()

# treelod_merge_media(<folder>): <folder> (the build tree's share/TreeLod/media) holds a link to every
# file of materials/ and of each technique's media/, GLSL/ included, as one resource location; a
# file name two folders both provide is an error. The install merges the same folders.
function(treelod_merge_media folder)
  get_property(media GLOBAL PROPERTY TREELOD_MEDIA_DIRS)
  if(IS_SYMLINK ${folder})
    file(REMOVE ${folder}) # a link to materials/ in trees configured before techniques had media
  endif()
  file(REMOVE_RECURSE ${folder})
  set(seen "")
  foreach(dir ${PROJECT_SOURCE_DIR}/materials ${media})
    file(GLOB_RECURSE files RELATIVE ${dir} CONFIGURE_DEPENDS ${dir}/*)
    foreach(file IN LISTS files)
      if(file IN_LIST seen)
        message(FATAL_ERROR "${dir}/${file}: another media folder already has ${file} (TreeLod's resource location is one folder)")
      endif()
      list(APPEND seen ${file})
      get_filename_component(parent ${folder}/${file} DIRECTORY)
      file(MAKE_DIRECTORY ${parent})
      file(CREATE_LINK ${dir}/${file} ${folder}/${file} SYMBOLIC)
    endforeach()
    install(DIRECTORY ${dir}/ DESTINATION ${TREELOD_INSTALL_DATADIR}/media)
  endforeach()
endfunction()
