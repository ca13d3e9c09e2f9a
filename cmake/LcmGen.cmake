# The one lcm-gen rule, included by CMakeLists.txt and fuzz/CMakeLists.txt: C++ headers of the
# message types generated at build time (not committed).
#
#   rths_lcm_gen_cpp(<target> <lcmtypes folder> <output folder> <comment>)
#
# adds the custom target <target> that writes <output folder>/rths/<type>.hpp for every
# <lcmtypes folder>/*.lcm, and sets <target>_DEFS (the .lcm files) in the caller's scope.
# Needs LCM_GEN (find_program(LCM_GEN lcm-gen REQUIRED)).
function(rths_lcm_gen_cpp target defs_dir out_dir comment)
  file(GLOB defs CONFIGURE_DEPENDS ${defs_dir}/*.lcm)
  set(headers)
  foreach(def ${defs})
    get_filename_component(stem ${def} NAME_WE)
    list(APPEND headers ${out_dir}/rths/${stem}.hpp)
  endforeach()
  add_custom_command(
    OUTPUT ${headers}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${out_dir}
    COMMAND ${LCM_GEN} --cpp --cpp-hpath ${out_dir} ${defs}
    DEPENDS ${defs}
    COMMENT "${comment}")
  add_custom_target(${target} DEPENDS ${headers})
  set(${target}_DEFS ${defs} PARENT_SCOPE)
endfunction()
