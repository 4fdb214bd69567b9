# node 2 twice
node 1 0 0 0
node 2 1 0 0
node 2 2 0 0
