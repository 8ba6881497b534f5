% ancestor, learned as a recursive program.
% Expected: ancestor(A,B) :- parent(A,B).   ancestor(A,B) :- parent(A,C), ancestor(C,B).
body_pred(parent/2).
metarules([ident, tailrec]).
setting(max_clauses(2)).
setting(max_inventions(0)).

parent(ann, amy).    parent(amy, bob).    parent(bob, carl).   parent(carl, dora).
parent(steve, amy).  parent(dora, eve).   parent(zed, yan).

pos(ancestor(ann, amy)).
pos(ancestor(ann, bob)).
pos(ancestor(ann, dora)).
pos(ancestor(steve, eve)).
pos(ancestor(bob, eve)).
neg(ancestor(amy, ann)).
neg(ancestor(eve, ann)).
neg(ancestor(zed, amy)).
neg(ancestor(bob, amy)).
