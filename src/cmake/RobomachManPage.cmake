# One man page from a tool's --help (see RobomachManPages.cmake):
#   cmake -DHELP2MAN=... -DTOOL=path -DNAME=tool -DVERSION=x.y.z -DDOC=page.md
#         -DDOCDIR=share/doc/robomach -DOUT=tool.1 -P RobomachManPage.cmake
set(ENV{LC_ALL} C.UTF-8)  # --help has UTF-8 (§, µ); help2man mangles it in the C locale
execute_process(COMMAND ${TOOL} --help OUTPUT_VARIABLE help RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${TOOL} --help exited with ${rc}")
endif()
# NAME: the first sentence of the description ("tool: what it does. ..."),
# without a trailing parenthesis, cut before a parenthesis or a comma when
# longer than 80 characters.
string(REGEX REPLACE "\nUsage:.*" "" what "${help}")
string(REPLACE "\n" " " what "${what}")
string(REGEX REPLACE "^${NAME}: *" "" what "${what}")
string(REGEX REPLACE "\\. .*" "" what "${what}")
string(REGEX REPLACE "[. ]+$" "" what "${what}")
string(REGEX REPLACE " \\([^()]*\\)$" "" what "${what}")  # a trailing "(docs/...)"
string(LENGTH "${what}" n)
if(n GREATER 80)
  string(REGEX REPLACE " \\(.*" "" what "${what}")
  string(LENGTH "${what}" n)
endif()
if(n GREATER 80)
  string(REGEX REPLACE ", .*" "" what "${what}")
endif()
set(see "")
if(DOC)
  set(see "The manual of ${NAME}: ${DOCDIR}/docs/${DOC}.\n.br\n")
endif()
file(WRITE ${OUT}.include
  "[NAME]\n${NAME} \\- ${what}\n"
  "[SEE ALSO]\n${see}The file formats: ${DOCDIR}/docs/formats.md.\n.br\n"
  "All tools, the library, how to cite: ${DOCDIR}/README.md.\n")
execute_process(COMMAND ${HELP2MAN} --no-info --locale=C.UTF-8 --version-string=${VERSION}
                        --include=${OUT}.include --output=${OUT}.tmp ${TOOL}
                RESULT_VARIABLE rc)
file(REMOVE ${OUT}.include)
if(NOT rc EQUAL 0)
  file(REMOVE ${OUT}.tmp)
  message(FATAL_ERROR "help2man failed on ${TOOL} (exit ${rc})")
endif()
file(RENAME ${OUT}.tmp ${OUT})
