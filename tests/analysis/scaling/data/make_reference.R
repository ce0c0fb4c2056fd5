# Writes the scaling tests' data sets and prints the reference values pasted into
# tests/analysis/scaling/*_test.cpp. Run from this folder: Rscript make_reference.R
# (R 4.2.2, BradleyTerry2 1.1-2; MLDS is not needed: its GLM is glm() on the design).
suppressMessages(library(BradleyTerry2))
# glm's default convergence (relative deviance change < 1e-8) leaves the standard errors
# of BTm's baseball fits at the weights of the iteration before the last (1e-6 off);
# converged fully they are those of the estimate. The coefficients agree either way.
tight <- glm.control(epsilon = 1e-14, maxit = 100)
options(digits = 12)
show <- function(label, x) cat(label, paste(formatC(x, digits = 12, format = "g"), collapse = " "), "\n")

## ---- citations (Stigler 1994), as in ?citations --------------------------------------
data(citations)
write.csv(data.frame(cited = rownames(citations), unclass(citations), check.names = FALSE),
          "citations.csv", row.names = FALSE, quote = FALSE)
citations.sf <- countsToBinomial(citations)
names(citations.sf)[1:2] <- c("journal1", "journal2")
for (link in c("logit", "probit")) {
  m <- BTm(cbind(win1, win2), journal1, journal2, ~ journal, id = "journal",
           data = citations.sf, family = binomial(link = link), control = tight)
  cat("== citations", link, "\n")
  show("coef", coef(m)); show("se", sqrt(diag(vcov(m))))
  show("deviance df aic null", c(deviance(m), df.residual(m), AIC(m), m$null.deviance))
}

## ---- baseball (Agresti 2002), as in ?baseball ----------------------------------------
data(baseball)
write.csv(baseball, "baseball.csv", row.names = FALSE, quote = FALSE)
for (link in c("logit", "probit")) {
  m1 <- BTm(cbind(home.wins, away.wins), home.team, away.team, data = baseball,
            id = "team", family = binomial(link = link), control = tight)
  cat("== baseball", link, "\n")
  show("coef", coef(m1)); show("se", sqrt(diag(vcov(m1))))
  show("deviance df aic null", c(deviance(m1), df.residual(m1), AIC(m1), m1$null.deviance))
  b <- baseball
  b$home.team <- data.frame(team = baseball$home.team, at.home = 1)
  b$away.team <- data.frame(team = baseball$away.team, at.home = 0)
  m2 <- BTm(cbind(home.wins, away.wins), home.team, away.team, formula = ~ team + at.home,
            id = "team", data = b, family = binomial(link = link), control = tight)
  cat("== baseball home", link, "\n")
  show("coef", coef(m2)); show("se", sqrt(diag(vcov(m2))))
  show("deviance df aic null", c(deviance(m2), df.residual(m2), AIC(m2), m2$null.deviance))
}

## ---- MLDS: simulated observer, quadruples and triads -------------------------------
# 8 stimuli (physical value x = 0, 1/7, ..., 1), psi = x^2, sigma = 0.15 (psi_8 = 1).
set.seed(30)
p <- 8; x <- (seq_len(p) - 1) / (p - 1); psi <- x^2; sigma <- 0.15
ids <- sprintf("s%d", seq_len(p))
mlds_sets <- function(k) t(combn(p, k))
write_choices <- function(file, task, canon, resp, screen_swap, screen_rev) {
  # canon: a<b<c<d (or a<b<c); resp 1 = canonical second pair (c,d) / (b,c) differs more.
  n <- nrow(canon); shown <- matrix("", n, 4); value <- matrix("", n, 4); choice <- integer(n)
  for (i in seq_len(n)) {
    if (task == "quadruple") {
      p1 <- canon[i, 1:2]; p2 <- canon[i, 3:4]
      if (screen_rev[i]) { p1 <- rev(p1); p2 <- rev(p2) }   # order inside each pair
      s <- if (screen_swap[i]) c(p2, p1) else c(p1, p2)      # which pair comes first
      second_chosen <- resp[i] == 1
      choice[i] <- if (xor(second_chosen, screen_swap[i])) 2L else 1L
    } else {
      s <- canon[i, ]
      if (screen_swap[i]) s <- rev(s)                        # c, b, a on screen
      choice[i] <- if (xor(resp[i] == 1, screen_swap[i])) 2L else 1L
      s <- c(s, NA)
    }
    shown[i, ] <- ifelse(is.na(s), "", ids[s])
    value[i, ] <- ifelse(is.na(s), "", sprintf("%.17g", x[s]))
  }
  d <- data.frame(participant = "sim", session = "s1", trial = seq_len(n), block = task,
                  task = task, question = "differs_more", practice = 0, catch = 0,
                  expected = "", shown_1 = shown[, 1], shown_2 = shown[, 2],
                  shown_3 = shown[, 3], shown_4 = shown[, 4], value_1 = value[, 1],
                  value_2 = value[, 2], value_3 = value[, 3], value_4 = value[, 4],
                  choice = choice, rt_ms = 800)
  write.csv(d, file, row.names = FALSE, quote = FALSE, na = "")
}
design_matrix <- function(canon, task) {
  X <- matrix(0, nrow(canon), p)
  for (i in seq_len(nrow(canon))) {
    if (task == "quadruple") X[i, canon[i, ]] <- c(1, -1, -1, 1)
    else X[i, canon[i, ]] <- c(1, -2, 1)
  }
  colnames(X) <- paste0("S", seq_len(p)); X
}
for (task in c("quadruple", "triad")) {
  sets <- mlds_sets(if (task == "quadruple") 4 else 3)
  canon <- sets[rep(seq_len(nrow(sets)), 3), ]                 # every set 3 times
  X <- design_matrix(canon, task)
  delta <- drop(X %*% psi)
  resp <- as.integer(delta + rnorm(nrow(X), 0, sigma) > 0)
  write_choices(paste0("mlds_", task, ".csv"), task, canon, resp,
                screen_swap = runif(nrow(X)) < 0.5, screen_rev = runif(nrow(X)) < 0.5)
  dsn <- data.frame(resp = resp, X)[, -2]                          # S1 dropped: psi_1 = 0
  g <- glm(resp ~ . - 1, family = binomial("probit"), data = dsn,
           control = glm.control(maxit = 50000, epsilon = 1e-14))
  cat("== mlds", task, "trials", nrow(X), "\n")
  show("coef", coef(g)); show("se", sqrt(diag(vcov(g))))
  show("deviance null aic loglik df", c(deviance(g), g$null.deviance, AIC(g), logLik(g), df.residual(g)))
  cat("normalised psi_p = 1: "); show("psi", c(0, coef(g)) / coef(g)[p - 1]); show("sigma", 1 / coef(g)[p - 1])
  show("DAF (null - dev)/null", (g$null.deviance - deviance(g)) / g$null.deviance)
}
