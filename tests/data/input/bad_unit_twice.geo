# two unit lines
unit mm
node 1 0 0 0
unit m
