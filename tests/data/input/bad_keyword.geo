# a mistyped keyword
node 1 0 0 0
nod 2 1 0 0
