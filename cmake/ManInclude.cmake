# Script mode (cmake -DPROGRAM=... -DOUTPUT=... -P ManInclude.cmake): writes the help2man include
# file of PROGRAM: a SUBCOMMANDS section with one subsection per subcommand, nested ones too
# ("submit slurm"), holding that subcommand's --help verbatim (roff-escaped), and SEE ALSO.
# Subcommands are read from the "Subcommands:" block of CLI11's --help.
if(NOT PROGRAM OR NOT OUTPUT)
  message(FATAL_ERROR "usage: cmake -DPROGRAM=<executable> -DOUTPUT=<file.h2m> -P ManInclude.cmake")
endif()
get_filename_component(_name "${PROGRAM}" NAME)

# The subcommand names listed in a --help text (empty if it lists none).
function(list_subcommands help out_var)
  set(_names "")
  string(FIND "${help}" "\nSubcommands:\n" _at)
  if(_at GREATER -1)
    string(SUBSTRING "${help}" ${_at} -1 _block)
    string(SUBSTRING "${_block}" 1 -1 _block)
    string(FIND "${_block}" "\n\n" _end)
    if(_end GREATER -1)
      string(SUBSTRING "${_block}" 0 ${_end} _block)
    endif()
    string(REGEX MATCHALL "\n  [a-z][a-z0-9_-]*" _lines "${_block}")
    foreach(_line IN LISTS _lines)
      string(STRIP "${_line}" _line)
      list(APPEND _names "${_line}")
    endforeach()
  endif()
  set(${out_var} "${_names}" PARENT_SCOPE)
endfunction()

# `text` as roff inside .nf/.fi: backslashes and hyphens escaped; lines that roff or help2man
# would read as requests or section markers (. ' / [) guarded with \&.
function(roff_escape text out_var)
  string(REPLACE "\\" "\\e" text "${text}")
  string(REPLACE "-" "\\-" text "${text}")
  string(REGEX REPLACE "\n([.'/[])" "\n\\\\&\\1" text "\n${text}")
  string(SUBSTRING "${text}" 1 -1 text)
  set(${out_var} "${text}" PARENT_SCOPE)
endfunction()

function(run_help args out_var)
  execute_process(COMMAND "${PROGRAM}" ${args} --help OUTPUT_VARIABLE _out ERROR_VARIABLE _err
                  RESULT_VARIABLE _rc)
  if(NOT _rc EQUAL 0)
    string(REPLACE ";" " " _shown "${args}")
    message(FATAL_ERROR "'${PROGRAM} ${_shown} --help' failed (${_rc}): ${_err}")
  endif()
  set(${out_var} "${_out}" PARENT_SCOPE)
endfunction()

run_help("" _top)
list_subcommands("${_top}" _queue)
set(_body "")
# Depth first, in --help order: each entry is a subcommand path with words joined by '/'.
while(_queue)
  list(POP_FRONT _queue _path)
  string(REPLACE "/" ";" _args "${_path}")
  string(REPLACE "/" " " _title "${_path}")
  run_help("${_args}" _help)
  string(REPLACE "${PROGRAM}" "${_name}" _help "${_help}")
  roff_escape("${_help}" _escaped)
  string(APPEND _body ".SS \"${_name} ${_title}\"\n.nf\n${_escaped}\n.fi\n")
  list_subcommands("${_help}" _children)
  list(TRANSFORM _children PREPEND "${_path}/")
  list(PREPEND _queue ${_children})
endwhile()

set(_text "")
if(_body)
  string(APPEND _text "[SUBCOMMANDS]\nEach subcommand's own options, as its --help prints them.\n${_body}\n")
endif()
if(_name STREQUAL "penumbra")
  string(APPEND _text "[ENVIRONMENT]\n.TP\n.B OCIO\nOpenColorIO config for display images when "
                      "\\-\\-ocio\\-config is not given; unset: the config built into penumbra (also "
                      "installed as share/penumbra/ocio/config.ocio).\n\n[SEE ALSO]\npenumbra\\-bench(1)\n")
else()
  string(APPEND _text "[SEE ALSO]\npenumbra(1)\n")
endif()
file(WRITE "${OUTPUT}" "${_text}")
