# Flattens each top-level .cl file (tools/embed_kernels.cpp: #include "..." resolved against the
# including file's folder and kernels/, each header once, #line markers kept so build errors name the
# real file and line, as LuxCore does) and embeds the results in the binary: it runs from anywhere.
add_executable(narval_embed_kernels ${CMAKE_SOURCE_DIR}/tools/embed_kernels.cpp)

function(narval_embed_kernels out_cpp function_name)
  cmake_parse_arguments(ARG "" "" "KERNELS;DEPENDS" ${ARGN})
  add_custom_command(OUTPUT ${out_cpp}
    COMMAND narval_embed_kernels ${out_cpp} ${function_name} ${CMAKE_SOURCE_DIR} ${ARG_KERNELS}
    DEPENDS narval_embed_kernels ${ARG_KERNELS} ${ARG_DEPENDS}
    COMMENT "Embedding OpenCL kernels into ${out_cpp}" VERBATIM)
endfunction()
