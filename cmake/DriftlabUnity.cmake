# Unity (batched) builds: a target's sources compiled a few at a time, each batch one translation
# unit that #includes its files, so the headers every file includes (Eigen, protobuf, gRPC,
# GoogleTest, CLI11) are parsed and their templates instantiated once per batch instead of once per
# file. The files of a batch share one translation unit, so names at namespace scope (anonymous
# namespaces included) are unique across a target's files.
#
# The batch files include their sources by the path relative to the source tree (-iquote
# <source>), so their text and their compile commands hold no absolute path, and ccache
# (CCACHE_BASEDIR, see CMakeLists.txt) reuses the objects across clones, as for ordinary sources.
# CMake's own UNITY_BUILD writes absolute paths into the batch files.
#
# -DDRIFTLAB_UNITY=OFF compiles every file alone (e.g. to check that each includes what it uses).
option(DRIFTLAB_UNITY "Compile each target's sources in batches (unity build)" ON)

# driftlab_unity(TARGET [BATCH n] [ALONE files...])
# Replaces TARGET's .cc sources by batch files of at most n sources (default 8), in the order the
# target lists them. Files in ALONE, generated files, and files with their own compile options or
# without the precompiled header stay single translation units.
function(driftlab_unity target)
  cmake_parse_arguments(U "" "BATCH" "ALONE" ${ARGN})
  if(NOT DRIFTLAB_UNITY)
    return()
  endif()
  if(NOT U_BATCH)
    set(U_BATCH 8)
  endif()
  get_target_property(sources ${target} SOURCES)
  get_target_property(source_dir ${target} SOURCE_DIR)
  set(batch)
  set(batches)
  set(count 0)
  foreach(source ${sources})
    get_filename_component(path ${source} ABSOLUTE BASE_DIR ${source_dir})
    get_source_file_property(generated ${path} GENERATED)
    get_source_file_property(options ${path} COMPILE_OPTIONS)
    get_source_file_property(no_pch ${path} SKIP_PRECOMPILE_HEADERS)
    set(alone FALSE)
    foreach(a ${U_ALONE})
      get_filename_component(a_path ${a} ABSOLUTE BASE_DIR ${source_dir})
      if(a_path STREQUAL path)
        set(alone TRUE)
      endif()
    endforeach()
    if(NOT path MATCHES "\\.cc$" OR generated OR options OR no_pch OR alone
       OR NOT path MATCHES "^${PROJECT_SOURCE_DIR}/")
      continue()
    endif()
    file(RELATIVE_PATH relative ${PROJECT_SOURCE_DIR} ${path})
    list(APPEND batch ${relative})
    set_source_files_properties(${path} TARGET_DIRECTORY ${target} PROPERTIES HEADER_FILE_ONLY ON)
    math(EXPR count "${count} + 1")
    if(count EQUAL U_BATCH)
      list(JOIN batch "," joined)
      list(APPEND batches ${joined})
      set(batch)
      set(count 0)
    endif()
  endforeach()
  if(batch)
    list(JOIN batch "," joined)
    list(APPEND batches ${joined})
  endif()
  set(index 0)
  foreach(joined ${batches})
    string(REPLACE "," ";" files "${joined}")
    set(content "// Unity batch ${index} of target ${target} (cmake/DriftlabUnity.cmake); generated.\n")
    foreach(file ${files})
      string(APPEND content "#include \"${file}\"\n")
    endforeach()
    set(out ${CMAKE_CURRENT_BINARY_DIR}/unity/${target}_${index}.cc)
    file(CONFIGURE OUTPUT ${out} CONTENT "${content}")
    target_sources(${target} PRIVATE ${out})
    math(EXPR index "${index} + 1")
  endforeach()
  target_compile_options(${target} PRIVATE "SHELL:-iquote ${PROJECT_SOURCE_DIR}")
endfunction()
