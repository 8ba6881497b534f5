/*  Background knowledge over the facts of docs/facts.md: a few derived predicates.

    A derived predicate is data, bk_rule(Head, Body), whose body the learner's meta-interpreter
    proves over the scene's facts; so a derived atom's confidence combines those of the facts it
    rests on, exactly as a learned clause's does, and an explanation lists those facts.
    A scene module imports this one (lv3d_bridge:load_scene/3) to see these rules.
*/
:- module(shape_bk, [derived/1, derived_uses/2, near_miss/2]).

%!  derived(?Name/Arity) is nondet.  The derived body predicates.
derived(P/A) :- clause(bk_rule(H, _), true), functor(H, P, A).

%!  derived_uses(?Name/Arity, -Facts) is nondet.  The fact predicates (Name/Arity) a derived
%   predicate's rule rests on: a modality that lacks one of them can never prove it.
derived_uses(P/A, Uses) :-
    clause(bk_rule(H, Body), true), functor(H, P, A),
    findall(Q/B, ( member(G, Body), functor(G, Q, B) ), Uses0), sort(Uses0, Uses).

%!  near_miss(+M, ?Fact) is nondet.  Fact, absent from scene module M, may be taken for a fact
%   perception missed (mil's option miss/1): never the structure (object/1, face_of/2), so that a
%   near proof still speaks of the object's own faces, and its open arguments range over the
%   object's other faces (other than the face it names).
near_miss(M, G) :-
    G =.. [P|Args], P \== object, P \== face_of,
    once(( member(F, Args), nonvar(F), M:face_of(O, F, _) )),
    include(nonvar, Args, Bound),
    maplist(sibling(M, O, Bound), Args).

sibling(_, _, _, X) :- nonvar(X), !.
sibling(M, O, Bound, X) :- M:face_of(O, X, _), \+ memberchk(X, Bound).

% two adjacent faces of the object meet at a right angle (cube, cuboid, prism caps)
bk_rule(right_corner(O), [face_of(O, F), adjacent(F, G), perpendicular(F, G)]).
% the face meets a neighbour at a right angle
bk_rule(perpendicular_neighbour(F), [adjacent(F, G), perpendicular(F, G)]).
% the face meets a neighbour at an acute interior angle (triangular prism sides, tetrahedron)
bk_rule(acute_neighbour(F), [acute(F, _)]).
% the face meets a neighbour at an obtuse interior angle (pentagonal/hexagonal prism sides, pyramids)
bk_rule(obtuse_neighbour(F), [obtuse(F, _)]).
% the face meets a neighbour at a regular pentagon's corner angle, 108 deg (pentagonal prism sides)
bk_rule(pentagonal_neighbour(F), [pentagonal_dihedral(F, _)]).
% the face meets a neighbour at a regular hexagon's corner angle, 120 deg (hexagonal prism sides)
bk_rule(hexagonal_neighbour(F), [hexagonal_dihedral(F, _)]).
% the face is a triangle and so is a neighbour (pyramids, tetrahedra: no triangle touches a triangle on a prism)
bk_rule(triangle_neighbour(F), [adjacent(F, G), triangle(G)]).
% the face has a quadrilateral neighbour (prisms, boxes)
bk_rule(quadrilateral_neighbour(F), [adjacent(F, G), quadrilateral(G)]).
% the face has a square neighbour (two adjacent squares: a cube)
bk_rule(square_neighbour(F), [adjacent(F, G), square(G)]).
