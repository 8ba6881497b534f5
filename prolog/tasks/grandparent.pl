% grandparent, learned by inventing parent: the program needs a predicate the background lacks.
% Expected: grandparent(A,B) :- grandparent_1(A,C), grandparent_1(C,B).
%           grandparent_1(A,B) :- mother(A,B).   grandparent_1(A,B) :- father(A,B).
body_pred(mother/2).
body_pred(father/2).
metarules([ident, chain]).
setting(max_clauses(3)).
setting(max_inventions(1)).

mother(ann, amy).      mother(ann, andy).    mother(amy, amelia).   mother(linda, gavin).
mother(amy, bob).
father(steve, amy).    father(steve, andy).  father(gavin, amelia). father(andy, spongebob).
father(gavin, bob).

pos(grandparent(ann, amelia)).
pos(grandparent(steve, amelia)).
pos(grandparent(ann, spongebob)).
pos(grandparent(steve, spongebob)).
pos(grandparent(linda, amelia)).
neg(grandparent(amy, amelia)).
neg(grandparent(ann, amy)).
neg(grandparent(steve, andy)).
