# coordinates in inches: not a unit yarnfort knows
unit inch
node 1 0 0 0
node 2 1 0 0
