/*---------------------------------------------------------------------------*\
    draglab: a stored, versioned drag law as a twoPhaseEulerFoam drag model.
    See draglab.H and docs/adapters.md.
\*---------------------------------------------------------------------------*/

#include "addToRunTimeSelectionTable.H"
#include "draglab.H"
#include "phasePair.H"

#include "draglab/draglab.h"

#include <chrono>
#include <vector>

// * * * * * * * * * * * * * * Static Data Members * * * * * * * * * * * * * //

namespace Foam {
namespace dragModels {
defineTypeNameAndDebug(draglab, 0);
addToRunTimeSelectionTable(dragModel, draglab, dictionary);
}  // namespace dragModels
}  // namespace Foam

namespace {

// The law entry, quoted ("gidaspow@1") or not (gidaspow@1: a word to OpenFOAM's tokenizer).
Foam::string lawReference(const Foam::dictionary& dict) {
  Foam::ITstream& is = dict.lookup("law");
  Foam::token t(is);
  if (t.isWord()) return t.wordToken();
  if (t.isString()) return t.stringToken();
  FatalIOErrorInFunction(dict) << "draglab: law must be a law reference such as gidaspow@1"
                               << Foam::exit(Foam::FatalIOError);
  return Foam::string();
}

}  // namespace

// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::dragModels::draglab::draglab(const dictionary& dict, const phasePair& pair,
                                   const bool registerObject)
    : dragModel(dict, pair, registerObject),
      lawRef_(lawReference(dict)),
      database_(dict.get<fileName>("database")),
      rangePolicy_(dict.getOrDefault<word>("rangePolicy", "error")),
      db_(nullptr),
      law_(nullptr),
      ownSeconds_(0),
      referenceSeconds_(0),
      evaluations_(0) {
  int policy = DRAGLAB_RANGE_ERROR;
  if (rangePolicy_ == "clamp") {
    policy = DRAGLAB_RANGE_CLAMP;
  } else if (rangePolicy_ == "extrapolate") {
    policy = DRAGLAB_RANGE_EXTRAPOLATE;
  } else if (rangePolicy_ != "error") {
    FatalIOErrorInFunction(dict) << "draglab: rangePolicy " << rangePolicy_
                                 << " is not one of error, clamp, extrapolate"
                                 << exit(FatalIOError);
  }

  database_.expand();
  if (!database_.isAbsolute()) {
    database_ = pair.phase1().mesh().time().path() / database_;
  }
  if (!isFile(database_)) {
    FatalIOErrorInFunction(dict) << "draglab: no database " << database_
                                 << " (the case's database entry, relative to the case)"
                                 << exit(FatalIOError);
  }
  if (draglab_db_open_readonly(database_.c_str(), &db_) != 0) {
    FatalIOErrorInFunction(dict) << "draglab: cannot open the database " << database_ << ": "
                                 << draglab_last_error() << exit(FatalIOError);
  }
  if (draglab_law_load(db_, lawRef_.c_str(), &law_) != 0) {
    const std::string why(draglab_last_error());
    draglab_db_close(db_);
    db_ = nullptr;
    FatalIOErrorInFunction(dict) << "draglab: cannot load the law " << lawRef_.c_str() << " from "
                                 << database_ << ": " << why.c_str() << exit(FatalIOError);
  }
  if (draglab_law_num_extra(law_) != 0) {
    FatalIOErrorInFunction(dict) << "draglab: the law " << lawRef_.c_str()
                                 << " is polydisperse (it needs " << draglab_law_num_extra(law_)
                                 << " extra inputs per cell); "
                                 << "twoPhaseEulerFoam has one particle diameter per phase"
                                 << exit(FatalIOError);
  }
  draglab_law_set_range_policy(law_, policy);

  if (dict.found("compareWith")) {
    // Not registered: the registry already holds this pair's drag model.
    const dictionary& compareDict = dict.subDict("compareWith");
    const word type(compareDict.get<word>("type"));
    auto cstrIter = dictionaryConstructorTablePtr_->cfind(type);
    if (!cstrIter.found()) {
      FatalIOErrorInFunction(compareDict)
          << "draglab: unknown compareWith type " << type << exit(FatalIOError);
    }
    reference_.reset(cstrIter()(compareDict, pair, false).ptr());
    Info << "draglab drag model: comparing with OpenFOAM's " << type << endl;
  }

  Info << "draglab drag model: law " << draglab_law_name(law_) << '@' << draglab_law_version(law_)
       << " (form " << draglab_law_form(law_) << ", hash "
       << word(std::string(draglab_law_hash(law_)).substr(0, 12)) << ") from " << database_
       << ", rangePolicy " << rangePolicy_ << endl;
}

// * * * * * * * * * * * * * * * * Destructor  * * * * * * * * * * * * * * * //

Foam::dragModels::draglab::~draglab() {
  if (law_) {
    draglab_law_free(law_);
  }
  if (db_) {
    draglab_db_close(db_);
  }
}

// * * * * * * * * * * * * * Private Member Functions  * * * * * * * * * * * //

void Foam::dragModels::draglab::evaluate(const scalarField& phi, const scalarField& Re,
                                         scalarField& result, const word& where) const {
  const label n = phi.size();
  if (n == 0) {
    return;
  }
  // scalar is double here (Debian builds OpenFOAM in double precision, WM_DP).
  std::vector<double> F(n);
  if (draglab_law_F_n(law_, size_t(n), phi.cdata(), Re.cdata(), F.data()) != 0) {
    // Find the first bad entry for the message.
    label bad = -1;
    double value = 0;
    for (label i = 0; i < n && bad < 0; ++i) {
      if (draglab_law_F(law_, phi[i], Re[i], &value) != 0) {
        bad = i;
      }
    }
    const std::string why(draglab_last_error());
    double phiMin = 0, phiMax = 0, reMin = 0, reMax = 0;
    draglab_law_validity(law_, &phiMin, &phiMax, &reMin, &reMax);
    FatalErrorInFunction << "draglab: the law " << draglab_law_name(law_) << '@'
                         << draglab_law_version(law_) << " cannot be evaluated at " << where << ' '
                         << bad << " (alpha." << pair_.dispersed().name() << " = "
                         << (bad >= 0 ? phi[bad] : 0)
                         << ", superficial Re = " << (bad >= 0 ? Re[bad] : 0)
                         << "): " << why.c_str() << "; its validity box is phi in [" << phiMin
                         << ", " << phiMax << "], Re in [" << reMin << ", " << reMax
                         << "] (rangePolicy " << rangePolicy_
                         << "; clamp or extrapolate evaluate outside it)" << exit(FatalError);
  }
  forAll(result, i) { result[i] = 24.0 * (1.0 - phi[i]) * F[i]; }
}

// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

Foam::tmp<Foam::volScalarField> Foam::dragModels::draglab::CdRe() const {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const volScalarField& alphaD = pair_.dispersed();
  const volScalarField& alphaC = pair_.continuous();
  // Superficial Reynolds number of the law: alpha_c |U_r| d / nu_c.
  const volScalarField Res(alphaC * pair_.Re());
  // phi = 1 - alpha_c (= alpha_d in two phases), kept within [0, 1].
  const volScalarField phi(min(max(1.0 - alphaC, scalar(0)), scalar(1)));

  tmp<volScalarField> tCdRe(
      new volScalarField(IOobject(IOobject::groupName("draglab:CdRe", pair_.name()),
                                  alphaD.mesh().time().timeName(), alphaD.mesh()),
                         alphaD.mesh(), dimensionedScalar(dimless, Zero)));
  volScalarField& cdRe = tCdRe.ref();

  evaluate(phi.primitiveField(), Res.primitiveField(), cdRe.primitiveFieldRef(), "cell");

  volScalarField::Boundary& bf = cdRe.boundaryFieldRef();
  forAll(bf, patchi) {
    scalarField values(bf[patchi].size());
    evaluate(phi.boundaryField()[patchi], Res.boundaryField()[patchi], values,
             "face of patch " + alphaD.mesh().boundary()[patchi].name() + ", face");
    bf[patchi] == values;
  }

  if (reference_.valid()) {
    const auto middle = Clock::now();
    const volScalarField ref(reference_->CdRe());
    ownSeconds_ += std::chrono::duration<double>(middle - start).count();
    referenceSeconds_ += std::chrono::duration<double>(Clock::now() - middle).count();
    evaluations_ += cdRe.size();
    forAll(bf, patchi) { evaluations_ += bf[patchi].size(); }
    scalar worst = 0;
    label where = -1;
    forAll(ref, celli) {
      const scalar d = mag(cdRe[celli] - ref[celli]) / max(mag(ref[celli]), VSMALL);
      if (d > worst) {
        worst = d;
        where = celli;
      }
    }
    scalar worstFace = 0;
    forAll(bf, patchi) {
      forAll(bf[patchi], facei) {
        const scalar r = ref.boundaryField()[patchi][facei];
        worstFace = max(worstFace, mag(bf[patchi][facei] - r) / max(mag(r), VSMALL));
      }
    }
    reduce(worst, maxOp<scalar>());
    reduce(worstFace, maxOp<scalar>());
    Info << "draglab compare: CdRe max relative difference " << worst << " over cells (cell "
         << where << ")"
         << ", " << worstFace << " over boundary faces; time per cell or"
         << " face: draglab " << 1e9 * ownSeconds_ / evaluations_ << " ns, OpenFOAM's "
         << 1e9 * referenceSeconds_ / evaluations_ << " ns (" << evaluations_ << " so far)" << endl;
  }
  return tCdRe;
}

// ************************************************************************* //
