# man-options.awk - the OPTIONS entries of kmorphd.8 from `kmorphd --help`:
# each "  --flag  KMORPH_VAR  meaning (default value)" line becomes a
# tagged paragraph, so the page lists exactly the settings the daemon has.
# web_root_default (-v) replaces the default the build tree's daemon
# prints, which is not the installed one.
function roff(s) {
  gsub(/\\/, "\\e", s)
  gsub(/-/, "\\-", s)
  return s
}
/^  --[a-z]/ && $2 ~ /^KMORPH_/ {
  flag = substr($1, 3)
  env = $2
  text = $0
  sub(/^ *--[^ ]+ +KMORPH_[A-Z_]+ +/, "", text)
  dflt = ""
  if (match(text, / \(default .*\)$/)) {
    dflt = substr(text, RSTART + 10, RLENGTH - 11)
    text = substr(text, 1, RSTART - 1)
  }
  if (flag == "web-root" && web_root_default != "") dflt = web_root_default
  printf ".TP\n.BI \"\\-\\-%s \" value \", %s=\" value\n", roff(flag), env
  printf "%s.\n", roff(toupper(substr(text, 1, 1)) substr(text, 2))
  if (dflt != "") printf "Default: %s.\n", roff(dflt)
}
