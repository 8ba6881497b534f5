% even and odd, learned together by mutual recursion: each target's clauses call the other.
% Expected: even(A) :- zero(A).   even(A) :- prev(A,B), odd(B).   odd(A) :- prev(A,B), even(B).
body_pred(zero/1).
body_pred(prev/2).
metarules([base, part]).
setting(max_clauses(3)).
setting(max_inventions(0)).

zero(0).
prev(A, B) :- integer(A), A > 0, B is A - 1.

pos(even(0)).  pos(even(2)).  pos(even(4)).  pos(even(6)).
pos(odd(1)).   pos(odd(3)).   pos(odd(5)).
neg(even(1)).  neg(even(3)).  neg(even(5)).
neg(odd(0)).   neg(odd(2)).   neg(odd(4)).
