# Page moves of issue #38 (docs as manuals). The merger applies this to code and test files,
# then deletes it:
#   git ls-files libsim libfit tools bench tests cmake CMakeLists.txt | xargs sed -i -f docs-moves.sed
# One substitution per moved page; a page that split maps to the page that holds the method
# (the sections the code cites are kept there). Only comment lines are rewritten (a line whose
# first non-blank is //, /*, * or #, or that has a // comment before the reference): string
# literals are printed by the CLI (help texts, notes) and must stay byte-identical, so their
# paths are left for a change of their own. Idempotent: no new name contains an old one.
/^[[:space:]]*\(\/\/\|\/\*\|\*\|#\)\|\/\/.*docs\//{
s|docs/meshing-and-membrane\.md|docs/methods/meshing-and-membrane.md|g
s|docs/meshing\.md|docs/methods/meshing-and-membrane.md|g
s|docs/cantilever-facts\.md|docs/methods/cantilever-facts.md|g
s|docs/drapemeter\.md|docs/methods/drapemeter.md|g
s|docs/benchmarks\.md|docs/methods/benchmarks.md|g
s|docs/validation\.md|docs/guide/validate.md|g
s|docs/extraction\.md|docs/methods/extraction.md|g
s|docs/reliability\.md|docs/methods/reliability.md|g
s|docs/materials\.md|docs/methods/materials.md|g
s|docs/bending\.md|docs/methods/bending.md|g
s|docs/fitting\.md|docs/methods/fitting.md|g
s|docs/statics\.md|docs/methods/statics.md|g
s|docs/photos\.md|docs/methods/photos.md|g
s|docs/clapp\.md|docs/methods/clapp.md|g
s|docs/seams\.md|docs/methods/seams.md|g
s|docs/acpm\.md|docs/methods/acpm.md|g
}
