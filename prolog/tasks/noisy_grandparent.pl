% grandparent from examples with one wrong label, grandparent(amy, ann), and a doubtful fact
% (father(gavin, amelia), confidence 0.4, below the coverage threshold of 0.5).
% The exact search finds no program (none proves the wrong positive); lv3d mil --noisy learns
% grandparent(A,B) :- grandparent_1(A,C), grandparent_1(C,B), grandparent_1 as mother or father.
body_pred(mother/2).
body_pred(father/2).
metarules([ident, chain]).
setting(max_clauses(3)).
setting(max_inventions(1)).

mother(ann, amy).   mother(ann, andy).   mother(amy, amelia).   mother(linda, gavin).
mother(amy, bob).   mother(linda, sam).
father(steve, amy). father(steve, andy). father(andy, spongebob). father(gavin, bob).
father(gavin, bea). father(sam, tom).
0.4::father(gavin, amelia).

pos(grandparent(ann, amelia)).
pos(grandparent(steve, amelia)).
pos(grandparent(ann, spongebob)).
pos(grandparent(steve, spongebob)).
pos(grandparent(ann, bob)).
pos(grandparent(linda, bob)).
pos(grandparent(linda, bea)).
pos(grandparent(linda, tom)).
pos(grandparent(amy, ann)).
neg(grandparent(amy, amelia)).
neg(grandparent(ann, amy)).
neg(grandparent(steve, andy)).
neg(grandparent(gavin, bob)).
