include Lancer_diag.Loc
