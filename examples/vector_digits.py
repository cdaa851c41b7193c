"""A variational autoencoder whose decoder draws digits with a few stroked cubic Bézier
curves, trained from raster images only, through vecfit's differentiable renderer (after
Li et al. 2020, section 6.3).

    python examples/vector_digits.py [--minutes 15] [--out out/digits] [--seed 0]
                                     [--threads 0] [--device cpu]

Data: the 1,797 handwritten digits scikit-learn ships (8x8, `sklearn.datasets.load_digits`,
no download), upscaled to 32x32 and drawn dark on white. Split fixed whatever the seed:
a permutation drawn with seed 0, its first 1,437 images train, the other 360 test.

The encoder (an MLP) maps an image to a 16-dimensional Gaussian; the decoder (an MLP)
maps a code to 4 cubic strokes (4 control points each, and a width), rendered black on
white at 32x32 by `vecfit.render_batch` (Monte Carlo, 2x2 samples). The loss is the
squared error summed over the pixels plus BETA times the KL divergence to N(0, I), BETA
rising from 0 over the first 5 epochs.

It writes to --out: `samples.svg` (an 8x8 grid decoded from random codes), `interpolation.svg`
(a row morphing between two test digits), `reconstructions.png` (test digits above their
vector reconstructions) and `report.json` (train and test loss per epoch, test PSNR).
Ctrl-C stops the training early and still writes them (exit 130).
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import vecfit  # first: it sets up threads before torch loads

import numpy as np
import torch
from torch import nn

from vecfit.io.files import atomic_write_text
from vecfit.io.png import save_png
from vecfit.scene import Path as CurvePath
from vecfit.scene import Scene, Shape, Solid

SIZE = 32         # pixels
STROKES = 4       # cubic strokes per digit
LATENT = 16
BETA = 0.2        # weight of the KL term against the summed squared error ...
BETA_WARMUP = 5   # ... reached linearly over the first epochs (else the codes collapse)
BATCH = 64
MARGIN = 2.0      # control points stay this far inside the canvas
TRAIN, TEST = 1437, 360
BLACK = torch.tensor([0.0, 0.0, 0.0, 1.0])


def load_digits(subset: int | None = None) -> tuple[torch.Tensor, torch.Tensor]:
    """(train, test) images [N, 32, 32] in [0, 1], dark ink on white."""
    from sklearn.datasets import load_digits as sklearn_digits

    ink = torch.tensor(sklearn_digits().images, dtype=torch.float32) / 16
    big = nn.functional.interpolate(ink[:, None], size=(SIZE, SIZE), mode="bicubic", align_corners=False)[:, 0]
    # Upscaling 8x8 blurs the strokes into grey; a contrast ramp makes them ink again.
    images = 1 - ((big - 0.2) / 0.5).clamp(0, 1)
    order = torch.randperm(len(images), generator=torch.Generator().manual_seed(0))
    train, test = images[order[:TRAIN]], images[order[TRAIN:TRAIN + TEST]]
    if subset:
        train, test = train[:subset], test[:max(subset // 4, 16)]
    return train, test


class Encoder(nn.Module):
    def __init__(self):
        super().__init__()
        self.body = nn.Sequential(nn.Flatten(), nn.Linear(SIZE * SIZE, 256), nn.ReLU(), nn.Linear(256, 128), nn.ReLU())
        self.mean, self.log_var = nn.Linear(128, LATENT), nn.Linear(128, LATENT)

    def forward(self, x):
        h = self.body(x)
        return self.mean(h), self.log_var(h)


class Decoder(nn.Module):
    """A code -> STROKES cubic strokes: control points [B, STROKES, 4, 2] in pixels and
    widths [B, STROKES] (1 to 4 px)."""

    def __init__(self):
        super().__init__()
        self.body = nn.Sequential(nn.Linear(LATENT, 128), nn.ReLU(), nn.Linear(128, 256), nn.ReLU(),
                                  nn.Linear(256, STROKES * 9))
        # Strokes start spread over the canvas (control points' biases uniform in logit
        # space), not all as dots at its centre, which the image gradient barely sees.
        with torch.no_grad():
            self.body[-1].bias.reshape(STROKES, 9)[:, :8].uniform_(-1.5, 1.5)

    def forward(self, z):
        out = self.body(z).reshape(-1, STROKES, 9)
        points = MARGIN + (SIZE - 2 * MARGIN) * torch.sigmoid(out[..., :8]).reshape(-1, STROKES, 4, 2)
        widths = 1.0 + 3.0 * torch.sigmoid(out[..., 8])
        return points, widths


def scenes_of(points: torch.Tensor, widths: torch.Tensor) -> list[Scene]:
    """One vecfit Scene per digit: its strokes as open cubic paths, black, round caps."""
    return [Scene(width=SIZE, height=SIZE, shapes=[
        Shape(geometry=CurvePath(points=points[b, k], degrees=np.array([3]), subpaths=[(0, 1, False)]),
              stroke=Solid(BLACK), stroke_width=widths[b, k], linecap="round", linejoin="round")
        for k in range(points.shape[1])]) for b in range(points.shape[0])]


def draw(points, widths, seed: int, threads: int, device: str, samples: int = 2) -> torch.Tensor:
    """The digits as grey images [B, 32, 32] (differentiable)."""
    images = vecfit.render_batch(scenes_of(points, widths), SIZE, SIZE, samples=samples, seed=seed,
                                 background=(1, 1, 1), threads=threads, interior_samples=1, device=device)
    return images[..., 0]  # black on white: the three channels are equal


def kl_divergence(mean, log_var):
    return -0.5 * (1 + log_var - mean ** 2 - log_var.exp()).sum(dim=1)


def evaluate(encoder, decoder, images, threads, device) -> tuple[float, float]:
    """Mean summed squared error of the reconstructions (codes at their means) and its PSNR."""
    with torch.no_grad():
        mean, _ = encoder(images)
        recon = draw(*decoder(mean), seed=0, threads=threads, device=device)
        mse = ((recon - images) ** 2).mean().item()
    return mse * SIZE * SIZE, 10 * math.log10(1 / max(mse, 1e-12))


# ----------------------------------------------------------------------------- outputs

def svg_of(digits: list[tuple[np.ndarray, np.ndarray]], columns: int, gap: float = 4.0) -> str:
    """Digits (points [S, 4, 2], widths [S]) as one SVG: a grid of 32-px cells, each a
    group of open cubic paths."""
    rows = math.ceil(len(digits) / columns)
    cell = SIZE + gap
    w, h = columns * cell + gap, rows * cell + gap
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w:g}" height="{h:g}" viewBox="0 0 {w:g} {h:g}">',
           f'<rect width="{w:g}" height="{h:g}" fill="white"/>']
    for i, (points, widths) in enumerate(digits):
        x, y = gap + (i % columns) * cell, gap + (i // columns) * cell
        out.append(f'<g id="digit-{i}" transform="translate({x:g} {y:g})" fill="none" stroke="black" '
                   f'stroke-linecap="round" stroke-linejoin="round">')
        for p, width in zip(points, widths):
            d = "M {:.3f} {:.3f} C {:.3f} {:.3f} {:.3f} {:.3f} {:.3f} {:.3f}".format(*p.reshape(-1))
            out.append(f'<path d="{d}" stroke-width="{float(width):.3f}"/>')
        out.append("</g>")
    out.append("</svg>")
    return "\n".join(out) + "\n"


def decoded(decoder, codes) -> list[tuple[np.ndarray, np.ndarray]]:
    with torch.no_grad():
        points, widths = decoder(codes)
    return [(points[i].numpy(), widths[i].numpy()) for i in range(len(codes))]


def write_outputs(out: Path, encoder, decoder, test, report, args) -> None:
    g = torch.Generator().manual_seed(args.seed)
    atomic_write_text(out / "samples.svg", svg_of(decoded(decoder, torch.randn(64, LATENT, generator=g)), 8))
    with torch.no_grad():
        mean, _ = encoder(test[:2])
    steps = torch.linspace(0, 1, 10)[:, None]
    atomic_write_text(out / "interpolation.svg", svg_of(decoded(decoder, (1 - steps) * mean[0] + steps * mean[1]), 10))
    shown = test[:16]
    with torch.no_grad():
        recon = draw(*decoder(encoder(shown)[0]), seed=0, threads=args.threads, device=args.device, samples=4)
    rows = torch.cat([torch.cat(list(shown), dim=1), torch.cat(list(recon), dim=1)], dim=0)
    big = rows.repeat_interleave(3, 0).repeat_interleave(3, 1)  # 3x, nearest: easier to see
    grey = big[..., None].clamp(0, 1)
    save_png(torch.cat([grey, grey, grey, torch.ones_like(grey)], dim=-1), out / "reconstructions.png")
    atomic_write_text(out / "report.json", json.dumps(report, indent=2) + "\n")


# ----------------------------------------------------------------------------- training

def train(args) -> int:
    torch.manual_seed(args.seed)
    if args.threads:
        torch.set_num_threads(args.threads)
    train_set, test_set = load_digits(args.subset)
    encoder, decoder = Encoder(), Decoder()
    opt = torch.optim.Adam([*encoder.parameters(), *decoder.parameters()], lr=args.lr)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    report = {"data": {"train": len(train_set), "test": len(test_set),
                       "split": "sklearn load_digits, permutation with seed 0: first 1437 train, next 360 test"},
              "settings": {"strokes": STROKES, "latent": LATENT, "beta": BETA, "beta_warmup_epochs": BETA_WARMUP,
                           "batch": BATCH, "lr": args.lr, "seed": args.seed, "size": SIZE, "samples": 2},
              "epochs": [], "interrupted": False}
    test_error, psnr = evaluate(encoder, decoder, test_set, args.threads, args.device)
    report["initial"] = {"test_error": test_error, "test_psnr": psnr}
    start, step, epoch = time.perf_counter(), 0, 0
    done = lambda: (args.minutes is not None and time.perf_counter() - start >= 60 * args.minutes) or \
        (args.epochs is not None and epoch >= args.epochs)
    try:
        while not done():
            order = torch.randperm(len(train_set), generator=torch.Generator().manual_seed(args.seed + epoch))
            total, count = 0.0, 0
            for first in range(0, len(order), BATCH):
                batch = train_set[order[first:first + BATCH]]
                mean, log_var = encoder(batch)
                z = mean + torch.randn_like(mean) * (0.5 * log_var).exp()
                recon = draw(*decoder(z), seed=step, threads=args.threads, device=args.device)
                error = ((recon - batch) ** 2).sum(dim=(1, 2))
                beta = BETA * min(1.0, (epoch + first / len(order)) / BETA_WARMUP)
                loss = (error + beta * kl_divergence(mean, log_var)).mean()
                opt.zero_grad()
                loss.backward()
                opt.step()
                total, count, step = total + error.sum().item(), count + len(batch), step + 1
                if args.minutes is not None and time.perf_counter() - start >= 60 * args.minutes:
                    break
            epoch += 1
            test_error, psnr = evaluate(encoder, decoder, test_set, args.threads, args.device)
            seconds = time.perf_counter() - start
            report["epochs"].append({"epoch": epoch, "train_error": total / max(count, 1), "test_error": test_error,
                                     "test_psnr": psnr, "seconds": round(seconds, 1)})
            if not args.quiet:
                print(f"epoch {epoch}: train {total / max(count, 1):.2f}, test {test_error:.2f} "
                      f"({psnr:.2f} dB), {seconds:.0f} s", file=sys.stderr, flush=True)
    except KeyboardInterrupt:
        report["interrupted"] = True
        print("interrupted: writing what was learnt so far", file=sys.stderr)
    if report["epochs"]:
        report["test_psnr"] = report["epochs"][-1]["test_psnr"]
    report["seconds"] = round(time.perf_counter() - start, 1)
    write_outputs(out, encoder, decoder, test_set, report, args)
    if not args.quiet:
        print(f"wrote {out}/samples.svg, interpolation.svg, reconstructions.png, report.json", file=sys.stderr)
    return 130 if report["interrupted"] else 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--minutes", type=float, default=15.0, help="stop after this many minutes (default 15)")
    ap.add_argument("--epochs", type=int, help="stop after this many epochs (whichever comes first)")
    ap.add_argument("--out", default="out/digits")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, default=0, help="0: all cores")
    ap.add_argument("--device", default="cpu", help="where vecfit renders: cpu, cuda, auto")
    ap.add_argument("--lr", type=float, default=2e-3)
    ap.add_argument("--subset", type=int, help="train on this many images only (a quick check)")
    ap.add_argument("-q", "--quiet", action="store_true")
    args = ap.parse_args(argv)
    try:
        return train(args)
    except vecfit.VecfitError as e:
        print(f"error: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
