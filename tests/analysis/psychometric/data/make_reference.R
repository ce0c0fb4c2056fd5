# Reference data and values for tests/analysis/psychometric (see SOURCE.md).
# Run: cd tests/analysis/psychometric/data && Rscript make_reference.R > reference_output.txt
# The data sets are simulated here (seeded) and written as CSV; the fits below read the
# CSV back, so the values are those of the committed files.
options(digits = 15)

simulate <- function(seed, x, n, psi) {
  set.seed(seed)
  data.frame(x = x, n_correct = rbinom(length(x), n, psi(x)), n_trials = n)
}
if (!file.exists("gauss_2afc.csv")) {
  x <- c(0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8)
  d <- simulate(31, x, 40, function(x) 0.5 + (1 - 0.5 - 0.04) * pnorm(x, 0.4, 0.15))
  write.csv(d, "gauss_2afc.csv", row.names = FALSE, quote = FALSE)
}
if (!file.exists("weibull_oddity.csv")) {
  x <- c(0.5, 1, 1.5, 2, 2.5, 3, 4, 6)
  d <- simulate(32, x, 30,
                function(x) 1/3 + (1 - 1/3 - 0.02) * (1 - exp(-(x / 2)^2.5)))
  write.csv(d, "weibull_oddity.csv", row.names = FALSE, quote = FALSE)
}
if (!file.exists("probit_yesno.csv")) {
  x <- seq(-2, 2, by = 0.5)
  d <- simulate(33, x, 20, function(x) pnorm(x, 0.3, 0.8))
  write.csv(d, "probit_yesno.csv", row.names = FALSE, quote = FALSE)
}

# The model: psi(x) = gamma + (1 - gamma - lambda) F(x; alpha, beta);
# Gaussian F = pnorm(x, alpha, beta), Weibull F = 1 - exp(-(x / alpha)^beta).
# Parameters searched: Gaussian (alpha, log beta[, lambda]); Weibull (log alpha,
# log beta[, lambda]); lambda free in [0, 0.06] or fixed.
F_of <- function(family, x, a, b)
  if (family == "gauss") pnorm(x, a, b) else 1 - exp(-(x / a)^b)
f_of <- function(family, x, a, b)
  if (family == "gauss") dnorm(x, a, b) else (b / a) * (x / a)^(b - 1) * exp(-(x / a)^b)
Finv <- function(family, p, a, b)
  if (family == "gauss") qnorm(p, a, b) else a * (-log(1 - p))^(1 / b)

fit <- function(d, family, gamma, lapse = NA, p_level = NA) {
  free_lapse <- is.na(lapse)
  unpack <- function(th) {
    a <- if (family == "gauss") th[1] else exp(th[1])
    list(a = a, b = exp(th[2]), l = if (free_lapse) th[3] else lapse)
  }
  nll <- function(th) {
    p <- unpack(th)
    psi <- gamma + (1 - gamma - p$l) * F_of(family, d$x, p$a, p$b)
    -sum(dbinom(d$n_correct, d$n_trials, psi, log = TRUE))
  }
  r <- range(d$x)
  a0 <- if (family == "gauss") quantile(d$x, c(0.25, 0.5, 0.75)) else
    log(quantile(d$x, c(0.25, 0.5, 0.75)))
  b0 <- log(c(0.1, 0.3, 1) * (if (family == "gauss") diff(r) else 3))
  best <- NULL
  for (a in a0) for (b in b0) {
    start <- c(a, b, if (free_lapse) 0.02)
    lo <- c(-Inf, -Inf, if (free_lapse) 0); hi <- c(Inf, Inf, if (free_lapse) 0.06)
    o <- nlminb(start, nll, lower = lo, upper = hi,
                control = list(rel.tol = 1e-15, x.tol = 1e-12, eval.max = 5000,
                               iter.max = 5000))
    if (is.null(best) || o$objective < best$objective) best <- o
  }
  # An independent check of the optimum: optim's L-BFGS-B (or BFGS without bounds)
  # from nlminb's answer must not find a better value.
  o2 <- if (free_lapse)
    optim(best$par, nll, method = "L-BFGS-B", lower = c(-Inf, -Inf, 0),
          upper = c(Inf, Inf, 0.06), control = list(factr = 1, pgtol = 0, maxit = 10000))
  else optim(best$par, nll, method = "BFGS", control = list(reltol = 1e-16, maxit = 10000))
  cat(sprintf("  optim after nlminb: objective change %.3g, max parameter change %.3g\n",
              best$objective - o2$value, max(abs(o2$par - best$par))))
  p <- unpack(best$par)
  psi <- gamma + (1 - gamma - p$l) * F_of(family, d$x, p$a, p$b)
  k <- d$n_correct; n <- d$n_trials
  sat <- sum(dbinom(k, n, k / n, log = TRUE))
  ll <- -best$objective
  dev <- 2 * (sat - ll)
  df <- nrow(d) - length(best$par)
  th <- Finv(family, 0.5, p$a, p$b)
  out <- c(alpha = p$a, beta = p$b, lambda = p$l, logLik = ll, deviance = dev, df = df,
           p_deviance = pchisq(dev, df, lower.tail = FALSE), threshold = th,
           slope = (1 - gamma - p$l) * f_of(family, th, p$a, p$b))
  if (!is.na(p_level)) {
    tp <- Finv(family, (p_level - gamma) / (1 - gamma - p$l), p$a, p$b)
    out <- c(out, threshold_p = tp,
             slope_p = (1 - gamma - p$l) * f_of(family, tp, p$a, p$b))
  }
  print(signif(out, 12))
  invisible(out)
}

cat("R", R.version$major, R.version$minor, "\n")
g <- read.csv("gauss_2afc.csv"); print(g)
cat("\n== gauss_2afc, cumulative Gaussian, gamma 0.5, lambda free in [0, 0.06]\n")
fit(g, "gauss", 0.5, NA, 0.75)
cat("\n== gauss_2afc, cumulative Gaussian, gamma 0.5, lambda fixed 0\n")
fit(g, "gauss", 0.5, 0, 0.75)
cat("\n== gauss_2afc, Weibull, gamma 0.5, lambda free in [0, 0.06]\n")
fit(g, "weibull", 0.5, NA, 0.75)

w <- read.csv("weibull_oddity.csv"); print(w)
cat("\n== weibull_oddity, Weibull, gamma 1/3, lambda free in [0, 0.06]\n")
fit(w, "weibull", 1/3, NA, 2/3)
cat("\n== weibull_oddity, Weibull, gamma 1/3, lambda fixed 0.01\n")
fit(w, "weibull", 1/3, 0.01, 2/3)
cat("\n== weibull_oddity, cumulative Gaussian, gamma 1/3, lambda fixed 0.01\n")
fit(w, "gauss", 1/3, 0.01, 2/3)

y <- read.csv("probit_yesno.csv"); print(y)
cat("\n== probit_yesno, cumulative Gaussian, gamma 0, lambda fixed 0\n")
fit(y, "gauss", 0, 0)
cat("\n== probit_yesno, glm(cbind(k, n - k) ~ x, binomial(\"probit\")): alpha = -b0/b1, beta = 1/b1\n")
m <- glm(cbind(n_correct, n_trials - n_correct) ~ x, binomial("probit"), data = y,
         control = glm.control(epsilon = 1e-14, maxit = 100))
b <- coef(m)
print(signif(c(b0 = b[[1]], b1 = b[[2]], alpha = -b[[1]] / b[[2]], beta = 1 / b[[2]],
               logLik = as.numeric(logLik(m)), deviance = deviance(m),
               df = df.residual(m)), 12))
