# tests/support/toml_edit.sh (sourced, not run): test variants of a shared TOML file
# (data/scenes/dpm_tiny.toml and the like) without a second copy. Same edits as
# tests/support/toml_edit.h:
#   toml_edit SRC EDIT...   prints SRC with the edits applied, every other line kept:
#     table.key=VALUE       replaces the key of [table] (it must be there)
#     table.+key=VALUE      adds the key at the end of [table]
#     table.key=-           drops the key (it must be there)
# VALUE is TOML as written in the file (0.03, '"dpm"', '["ergun@1"]'). An edit that finds no
# [table] or no key prints a message on stderr and returns 1 (a variant that silently equals SRC
# would test nothing new).
toml_edit() {  # toml_edit SRC EDIT...
  local text
  text="$(cat "$1")" || return 1
  shift
  local edit table key value
  for edit in "$@"; do
    table="${edit%%.*}"
    key="${edit#*.}"
    value="${key#*=}"
    key="${key%%=*}"
    text="$(printf '%s\n' "$text" | awk -v table="$table" -v key="$key" -v value="$value" '
      function flush_add() { if (adding && current == table) { print substr(key, 2) " = " value; adding = 0; done = 1 } }
      BEGIN { adding = (substr(key, 1, 1) == "+") }
      /^\[/ { flush_add(); current = substr($0, 2, index($0, "]") - 2); if (current == table) found = 1 }
      !adding && current == table && index($0, key) == 1 && substr($0, length(key) + 1) ~ /^[ \t]*=/ {
        if (value != "-") print key " = " value
        done = 1
        next }
      { print }
      END { flush_add()
            if (!found) { print "toml_edit: no table [" table "]" > "/dev/stderr"; exit 1 }
            if (!done) { print "toml_edit: no key " key " in [" table "]" > "/dev/stderr"; exit 1 } }')" ||
      return 1
  done
  printf '%s\n' "$text"
}
